// avs node list | info: the ROS 2 nodes of running graphs, read from ros_discovery_info (what
// `ros2 node list` reads) and DDS discovery (each node's readers and writers by GUID).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <thread>

#include "avs/runtime/parameters.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/ros_discovery.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"

namespace avs::cli {

namespace {

struct NodeOptions {
  int domain = 0;  // add_domain_option
  double wait_s = 1.5;
  std::string node;
  bool verbose = false;
};

std::chrono::milliseconds wait_of(const NodeOptions& o) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(o.wait_s * 1000));
}

std::string full_name(const runtime::NodeEntities& n) {
  return (n.node_namespace == "/" ? "" : n.node_namespace) + "/" + n.node_name;
}

struct NodeEndpoint {
  std::string topic;  ///< DDS name
  std::string type;   ///< DDS type name
};

/// Every remote reader and writer DDS discovery shows (built-in topics), by GUID.
std::map<runtime::Gid, NodeEndpoint> endpoints(const runtime::dds::Participant& participant) {
  runtime::dds::EndpointDiscovery discovery(participant);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  discovery.update();
  std::map<runtime::Gid, NodeEndpoint> out;
  for (const auto& [key, e] : discovery.endpoints()) out[e.key] = {e.topic, e.type_name};
  return out;
}

std::vector<runtime::NodeEntities> nodes_seen(const runtime::dds::Participant& participant,
                                              const NodeOptions& o) {
  std::vector<runtime::NodeEntities> nodes;
  for (auto& p : runtime::read_ros_discovery(participant, wait_of(o))) {
    for (auto& n : p.nodes) nodes.push_back(std::move(n));
  }
  std::sort(nodes.begin(), nodes.end(),
            [](const auto& a, const auto& b) { return full_name(a) < full_name(b); });
  return nodes;
}

void run_list(const NodeOptions& o) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  const auto nodes = nodes_seen(participant, o);
  for (const auto& n : nodes) std::printf("%s\n", full_name(n).c_str());
  if (nodes.empty()) {
    std::fprintf(stderr, "no ROS 2 node on domain %d (no ros_discovery_info within %s s)\n",
                 o.domain, runtime::format_number(o.wait_s).c_str());
  }
}

/// "/depth/image: sensor_msgs/msg/Image", or for a service request reader
/// "/decode/get_parameters: rcl_interfaces/srv/GetParameters".
std::string describe(const NodeEndpoint& e, bool verbose) {
  std::string name = e.topic;
  std::string type = runtime::to_ros_type_name(e.type);
  if (name.rfind("rt/", 0) == 0) name = runtime::from_dds_topic_name(name);
  const std::string request = "Request";
  if (name.rfind("rq/", 0) == 0 && name.size() > request.size() + 3 &&
      name.compare(name.size() - request.size(), request.size(), request) == 0) {
    name = name.substr(2, name.size() - 2 - request.size());
    const std::string suffix = "_Request";
    if (type.size() > suffix.size() &&
        type.compare(type.size() - suffix.size(), suffix.size(), suffix) == 0) {
      type.resize(type.size() - suffix.size());
    }
  }
  return name + ": " + type + (verbose ? "  (DDS " + e.topic + ", " + e.type + ")" : "");
}

void run_info(const NodeOptions& o) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  const auto nodes = nodes_seen(participant, o);
  const std::string wanted = o.node.front() == '/' ? o.node : "/" + o.node;
  const runtime::NodeEntities* node = nullptr;
  for (const auto& n : nodes) {
    if (full_name(n) == wanted) node = &n;
  }
  if (node == nullptr) {
    std::string seen;
    for (const auto& n : nodes) seen += (seen.empty() ? "" : ", ") + full_name(n);
    throw runtime::Error("no node " + wanted + " on domain " + std::to_string(o.domain) +
                         " (nodes: " + (seen.empty() ? "none" : seen) + ")");
  }
  const auto known = endpoints(participant);
  std::set<std::string> subscribers, publishers, services;
  for (const auto& gid : node->readers) {
    const auto it = known.find(gid);
    if (it == known.end()) continue;
    (it->second.topic.rfind("rq/", 0) == 0 ? services : subscribers)
        .insert(describe(it->second, o.verbose));
  }
  for (const auto& gid : node->writers) {
    const auto it = known.find(gid);
    if (it == known.end() || it->second.topic.rfind("rr/", 0) == 0) continue;
    publishers.insert(describe(it->second, o.verbose));
  }
  std::printf("%s\n", wanted.c_str());
  for (const auto& [title, set] :
       {std::pair{"Subscribers", &subscribers}, std::pair{"Publishers", &publishers},
        std::pair{"Service Servers", &services}}) {
    std::printf("  %s:\n", title);
    for (const auto& line : *set) std::printf("    %s\n", line.c_str());
  }
}

void add_node_command(Command& app) {
  auto* node = app.add_subcommand(
      "node", "ROS 2 nodes of running graphs (each component is one), as `ros2 node` shows them");
  node->require_subcommand(1);
  static NodeOptions list_o;
  auto* list = node->add_subcommand("list", "Every node seen on ros_discovery_info");
  add_domain_option(list, list_o.domain);
  list->add_option("--wait", list_o.wait_s, "seconds to listen")
      ->check_range(0.1, 3600)
      ->capture_default_str();
  list->callback([] {
    stop_on_interrupt();
    run_list(list_o);
  });
  static NodeOptions info_o;
  auto* info = node->add_subcommand(
      "info", "A node's subscriptions, publications and services (ROS names and types)");
  add_domain_option(info, info_o.domain);
  info->add_option("node", info_o.node, "node: decode or /ns/decode")->required();
  info->add_option("--wait", info_o.wait_s, "seconds to listen")
      ->check_range(0.1, 3600)
      ->capture_default_str();
  info->add_flag("-v,--verbose", info_o.verbose, "DDS topic and type names too");
  info->callback([] {
    stop_on_interrupt();
    run_info(info_o);
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_node_command);

}  // namespace avs::cli
