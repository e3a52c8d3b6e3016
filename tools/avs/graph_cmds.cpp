// avs check / avs components / avs container: graph validation, the component catalogue,
// and running one container of a graph in this process.
#include <csignal>
#include <iostream>
#include <thread>

#include "avs/graph/graph.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "graph_loading.hpp"

namespace avs::cli {

std::optional<graph::Graph> load_or_report(const std::string& file,
                                           const std::vector<std::string>& words) {
  std::vector<std::string> rest;
  const auto args = graph::parse_arg_overrides(words, &rest);
  if (!rest.empty()) {
    std::cerr << "avs: unexpected argument '" << rest.front() << "' (arguments are NAME:=VALUE)\n";
    return std::nullopt;
  }
  graph::LoadResult result = graph::load_graph(file, args);
  for (const auto& d : result.errors) std::cerr << d.str() << "\n";
  if (!result.ok()) return std::nullopt;
  apply_environment(*result.graph);
  return std::move(*result.graph);
}

void add_check_command(Command& app) {
  auto* cmd = app.add_subcommand("check", "Validate a YAML graph without starting anything");
  static std::string file;
  static std::vector<std::string> words;
  cmd->add_option("file", file, "graph YAML file")->required();
  cmd->add_option("args", words, "argument overrides NAME:=VALUE");
  cmd->callback([] {
    auto g = load_or_report(file, words);
    if (!g) {
      exit_status() = 2;
      return;
    }
    std::size_t components = 0;
    for (const auto& c : g->containers) components += c.components.size();
    std::cout << file << ": ok (" << g->containers.size() << " container(s), " << components
              << " component(s))\n";
  });
}

void add_components_command(Command& app) {
  auto* cmd =
      app.add_subcommand("components", "List component types with their parameters and topics");
  static std::string only;
  static bool verbose = false;
  cmd->add_option("type", only, "show only this type");
  cmd->add_flag("-v,--verbose", verbose, "DDS type names too");
  cmd->footer("[live]: `avs param set` changes it while the graph runs; the others need a "
              "restart (docs/operate.md).");
  cmd->callback([] {
    // ROS names where a person reads (issue 18 section 4); the DDS name only with -v.
    const auto type_text = [](const std::string& dds_type) {
      const std::string ros = runtime::to_ros_type_name(dds_type);
      return verbose ? ros + ", DDS " + dds_type : ros;
    };
    bool found = false;
    for (const auto* c : runtime::ComponentRegistry::instance().all()) {
      if (!only.empty() && c->spec.type != only) continue;
      found = true;
      std::cout << c->spec.type << ": " << c->spec.description << "\n";
      for (const auto& p : c->spec.parameters) {
        std::cout << "  param " << p.name << " (" << runtime::to_string(p.type)
                  << ") = " << runtime::to_string(p.default_value);
        if (!p.unit.empty()) std::cout << " " << p.unit;
        std::cout << runtime::range_text(p.min, p.max);
        // Which ones `avs param set` changes while the graph runs (issue 18 section 1).
        std::cout << (p.dynamic ? "  [live]" : "") << "  " << p.description << "\n";
      }
      for (const auto& p : c->spec.publishes) {
        std::cout << "  publishes " << p.name << " -> " << p.default_topic << " ["
                  << type_text(p.dds_type) << "]\n";
      }
      for (const auto& p : c->spec.subscribes) {
        std::cout << "  subscribes " << p.name << " <- " << p.default_topic << " ["
                  << type_text(p.dds_type) << "]\n";
      }
    }
    if (!found) {
      std::cerr << "avs: no component type '" << only << "'\n";
      exit_status() = 1;
    }
  });
}

void add_container_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "container", "Run one container of a graph in this process (what `avs launch` starts)");
  static std::string file;
  static std::string name;
  static std::vector<std::string> words;
  cmd->add_option("file", file, "graph YAML file")->required();
  cmd->add_option("--name", name, "container to run")->required();
  cmd->add_option("args", words, "argument overrides NAME:=VALUE");
  cmd->callback([] {
    auto g = load_or_report(file, words);
    if (!g) {
      exit_status() = 2;
      return;
    }
    const graph::ContainerSpec* spec = g->find_container(name);
    if (spec == nullptr) {
      std::cerr << "avs: " << file << " has no container '" << name << "'\n";
      exit_status() = 2;
      return;
    }
    // Signals go to a dedicated thread that stops the container cleanly.
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    runtime::Container container(*g, *spec);
    std::thread waiter([&] {
      int sig = 0;
      sigwait(&signals, &sig);
      if (sig != 0) container.stop();
    });
    int status = 1;
    try {
      status = container.run();
    } catch (const std::exception& e) {
      std::cerr << "avs: container '" << name << "': " << e.what() << "\n";
    }
    pthread_kill(waiter.native_handle(), SIGTERM);  // release the waiter if no signal came
    waiter.join();
    exit_status() = status;
  });
}

}  // namespace avs::cli
