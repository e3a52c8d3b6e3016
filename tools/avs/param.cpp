// avs param list | get | set | describe | dump: the parameters of a running graph's
// components, through ROS 2's parameter services (each component is a node; the container
// answers for it, docs/operate.md). `ros2 param` habits carry over.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "avs/runtime/dds.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"
#include "parameter_client.hpp"

namespace avs::cli {

namespace {

struct ParamOptions {
  int domain = 0;  // add_domain_option
  double timeout_s = 5.0;
  std::string node;
  std::string name;
  std::string value;
};

std::chrono::milliseconds timeout_of(const ParamOptions& o) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(o.timeout_s * 1000));
}

/// The participant and the node a command talks to.
struct Session {
  explicit Session(const ParamOptions& o)
      : participant(o.domain, environment_partition()),
        client(participant, resolve_node(participant, o.node, timeout_of(o)), timeout_of(o)) {}
  runtime::dds::Participant participant;
  ParameterClient client;
};

std::string kind_of(const ParameterDescription& d) {
  return runtime::to_string(d.type) + (d.read_only ? ", restart" : ", dynamic");
}

void print_node(ParameterClient& client) {
  const auto names = client.list();
  const auto descriptions = client.describe(names);
  std::size_t width = 0;
  for (const auto& n : names) width = std::max(width, n.size());
  std::printf("%s:\n", client.node().c_str());
  for (const auto& d : descriptions) {
    std::printf("  %-*s  %s\n", static_cast<int>(width), d.name.c_str(), kind_of(d).c_str());
  }
}

void run_list(const ParamOptions& o) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  std::vector<std::string> nodes;
  if (o.node.empty()) {
    nodes = discover_parameter_nodes(participant, std::chrono::milliseconds(1500));
    if (nodes.empty()) {
      throw runtime::Error("no node offers parameter services (is a graph running on domain " +
                           std::to_string(o.domain) + "?)");
    }
  } else {
    nodes.push_back(resolve_node(participant, o.node, timeout_of(o)));
  }
  for (const auto& node : nodes) {
    ParameterClient client(participant, node, timeout_of(o));
    print_node(client);
  }
}

/// The description of one parameter; throws when the node does not have it.
ParameterDescription describe_one(ParameterClient& client, const std::string& name) {
  ParameterDescription d = client.describe({name}).front();
  if (d.type == runtime::RosParameterType::not_set) {
    std::string names;
    for (const auto& n : client.list()) names += (names.empty() ? "" : ", ") + n;
    throw runtime::Error("unknown parameter '" + name + "' of " + client.node() +
                         " (it has: " + names + ")");
  }
  return d;
}

void run_get(const ParamOptions& o) {
  Session s(o);
  const auto value = s.client.get({o.name}).front();
  if (!value) describe_one(s.client, o.name);  // throws the unknown-parameter error
  if (!value) throw runtime::Error(o.name + " of " + s.client.node() + " has no value avs reads");
  std::printf("%s\n", runtime::to_string(*value).c_str());
}

void run_describe(const ParamOptions& o) {
  Session s(o);
  const ParameterDescription d = describe_one(s.client, o.name);
  std::printf("Parameter name: %s\n  Type: %s\n  Description: %s\n  Constraints: %s\n",
              d.name.c_str(), runtime::to_string(d.type).c_str(), d.description.c_str(),
              d.constraints.c_str());
  if (d.range) {
    std::printf("  Min value: %s\n  Max value: %s\n",
                runtime::format_number(d.range->first).c_str(),
                runtime::format_number(d.range->second).c_str());
  }
  std::printf("  Read only: %s\n",
              d.read_only ? "true (read at start: restart to change)" : "false");
}

void run_set(const ParamOptions& o) {
  Session s(o);
  // The type of the value comes from the node's description, so that "30" is an integer for
  // an integer parameter and a number for a real one; text that is not of the type goes as a
  // string and the node says what it expected.
  const ParameterDescription d = s.client.describe({o.name}).front();
  const auto type = runtime::param_type(d.type);
  const runtime::ParamValue value =
      type ? runtime::parse_param_text(*type, o.value) : runtime::ParamValue{o.value};
  const auto before = s.client.get({o.name}).front();
  const std::string reason = s.client.set({{o.name, value}}).front();
  if (!reason.empty()) {
    std::fprintf(stderr, "avs param set: %s refused %s = %s: %s\n", s.client.node().c_str(),
                 o.name.c_str(), o.value.c_str(), reason.c_str());
    exit_status() = 1;
    return;
  }
  std::printf("%s: %s = %s%s\n", s.client.node().c_str(), o.name.c_str(),
              runtime::to_string(value).c_str(),
              before ? (" (was " + runtime::to_string(*before) + ")").c_str() : "");
}

void run_dump(const ParamOptions& o) {
  Session s(o);
  const auto names = s.client.list();
  const auto values = s.client.get(names);
  std::printf(
      "# %s: its parameters now (avs param dump); the lines below are a component's\n"
      "# `parameters:` block in a graph (docs/graphs.md).\n",
      s.client.node().c_str());
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!values[i]) continue;
    std::printf("%s: %s\n", names[i].c_str(), runtime::to_yaml_text(*values[i]).c_str());
  }
}

void add_common(Command* cmd, ParamOptions& o, bool node_required, bool name, bool value) {
  add_domain_option(cmd, o.domain);
  cmd->add_option("--wait,--timeout", o.timeout_s,
                  "seconds to wait for the node and each answer (--wait as in avs topic/node)")
      ->check_range(0.1, 3600)
      ->capture_default_str();
  auto* node = cmd->add_option("node", o.node,
                               "node: a component's name (decode) or its full name (/ns/decode)");
  if (node_required) node->required();
  if (name) cmd->add_option("name", o.name, "parameter name")->required();
  if (value) {
    cmd->add_option("value", o.value, "new value as YAML writes it: 30, 0.5, true, [1, 2], text")
        ->required();
  }
}

void add_param_command(Command& app) {
  auto* param = app.add_subcommand(
      "param",
      "Read and change the parameters of a running graph's components (ROS 2 parameter "
      "services; each component is a node)");
  param->require_subcommand(1);
  param->footer(
      "Dynamic parameters change while the graph runs, between two callbacks of the component; "
      "the others are read when it starts (restart). Every change goes out on "
      "/parameter_events. See docs/operate.md.");

  static ParamOptions list_o;
  auto* list = param->add_subcommand(
      "list",
      "Parameters of NODE (or of every node seen), each with its type and whether it is "
      "dynamic");
  add_common(list, list_o, false, false, false);
  list->callback([] {
    stop_on_interrupt();
    run_list(list_o);
  });

  static ParamOptions get_o;
  auto* get = param->add_subcommand("get", "Print the value of one parameter");
  add_common(get, get_o, true, true, false);
  get->callback([] {
    stop_on_interrupt();
    run_get(get_o);
  });

  static ParamOptions describe_o;
  auto* describe = param->add_subcommand(
      "describe", "Type, description, range and whether a parameter is dynamic");
  add_common(describe, describe_o, true, true, false);
  describe->callback([] {
    stop_on_interrupt();
    run_describe(describe_o);
  });

  static ParamOptions set_o;
  auto* set = param->add_subcommand(
      "set",
      "Change a dynamic parameter; a refused change says why (unknown, not dynamic, out "
      "of range) and exits 1");
  add_common(set, set_o, true, true, true);
  set->callback([] {
    stop_on_interrupt();
    run_set(set_o);
  });

  static ParamOptions dump_o;
  auto* dump = param->add_subcommand(
      "dump", "Print every parameter of NODE as YAML, loadable as its `parameters:` block");
  add_common(dump, dump_o, true, false, false);
  dump->callback([] {
    stop_on_interrupt();
    run_dump(dump_o);
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_param_command);

}  // namespace avs::cli
