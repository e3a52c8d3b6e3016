// avs deploy check FILE / avs deploy config FILE --host NAME: validate a deployment and show
// the Cyclone DDS configuration `avs launch FILE --host NAME` gives its containers.
#include <iostream>

#include "avs/deploy/deployment.hpp"
#include "commands.hpp"

namespace avs::cli {
namespace {

std::optional<deploy::Deployment> load_deployment_or_report(const std::string& file,
                                                            const std::vector<std::string>& words) {
  std::vector<std::string> rest;
  const auto overrides = graph::parse_arg_overrides(words, &rest);
  if (!rest.empty()) {
    std::cerr << "avs: unexpected argument '" << rest.front() << "' (arguments are NAME:=VALUE)\n";
    return std::nullopt;
  }
  deploy::LoadResult r = deploy::load_deployment(file, overrides);
  for (const auto& e : r.errors) std::cerr << e.str() << "\n";
  if (!r.ok()) return std::nullopt;
  return std::move(*r.deployment);
}

void add_deploy_command(Command& app) {
  auto* cmd = app.add_subcommand("deploy", "Deployments over several hosts (docs/deploy.md)");
  cmd->require_subcommand(1);

  auto* check =
      cmd->add_subcommand("check", "Validate a deployment and its graph; list the placement");
  static std::string check_file;
  static std::vector<std::string> check_words;
  check->add_option("file", check_file, "deployment YAML")->required();
  check->add_option("args", check_words, "graph argument overrides NAME:=VALUE");
  check->callback([] {
    auto d = load_deployment_or_report(check_file, check_words);
    if (!d) {
      exit_status() = 2;
      return;
    }
    std::cout << check_file << ": ok (graph " << d->graph_file << ", domain " << d->domain_id
              << (d->partition.empty() ? "" : ", partition " + d->partition)
              << (d->discovery.multicast ? ", multicast" : ", unicast peers")
              << (d->security.enabled ? ", security on" : "")
              << (d->shared_memory.enabled ? ", shared memory" : "") << ")\n";
    for (const auto& h : d->hosts) {
      std::cout << "  host " << h.name;
      if (!h.address.empty()) std::cout << " " << h.address;
      if (!h.interface.empty()) std::cout << " (" << h.interface << ")";
      std::cout << ":";
      for (const auto& c : h.containers) std::cout << " " << c;
      std::cout << "\n";
    }
  });

  // `config` and `env`: one host's DDS settings, as XML or as shell exports.
  struct HostQuery {
    std::string file, host, participant = "observer";
    std::vector<std::string> words;
  };
  auto add_host_query = [cmd](const char* name, const char* help, HostQuery& q,
                              void (*print)(const deploy::Deployment&, const std::string&)) {
    auto* sub = cmd->add_subcommand(name, help);
    sub->add_option("file", q.file, "deployment YAML")->required();
    sub->add_option("--host", q.host, "host name")->required();
    sub->add_option("--participant", q.participant,
                    "identity when security is on: a container name, or observer (reads every "
                    "topic, writes none)")
        ->capture_default_str();
    sub->add_option("args", q.words, "graph argument overrides NAME:=VALUE");
    sub->callback([&q, name, print] {
      auto d = load_deployment_or_report(q.file, q.words);
      const deploy::Host* h = d ? d->find_host(q.host) : nullptr;
      if (d && h == nullptr) {
        std::cerr << "avs deploy " << name << ": no host '" << q.host << "' in " << q.file << "\n";
      }
      if (h == nullptr) {
        exit_status() = 2;
        return;
      }
      print(*d, deploy::cyclone_config(*d, *h, q.participant));
    });
  };
  static HostQuery config_query, env_query;
  add_host_query("config", "Print the Cyclone DDS XML (CYCLONEDDS_URI) of one host's participants",
                 config_query, [](const deploy::Deployment&, const std::string& xml) {
                   std::cout << xml << "\n";
                 });
  add_host_query(
      "env",
      "Print shell exports (CYCLONEDDS_URI, AVS_DOMAIN_ID, AVS_PARTITION) for tools run on a "
      "host: eval \"$(avs deploy env FILE --host B)\"; avs topic list",
      env_query, [](const deploy::Deployment& d, const std::string& xml) {
        std::cout << "export CYCLONEDDS_URI='" << xml << "'\n";
        std::cout << "export AVS_DOMAIN_ID=" << d.domain_id << "\n";
        if (d.partition.empty()) {
          std::cout << "unset AVS_PARTITION\n";
        } else {
          std::cout << "export AVS_PARTITION='" << d.partition << "'\n";
        }
      });
}

}  // namespace

AVS_REGISTER_COMMAND(add_deploy_command)

}  // namespace avs::cli
