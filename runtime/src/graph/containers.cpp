// Reading containers (processes) and the graph-wide topic type check.
#include <algorithm>

#include "avs/runtime/component.hpp"
#include "avs/runtime/topic_name.hpp"
#include "components.hpp"

namespace avs::graph {
namespace detail {
namespace {

const std::vector<std::string> container_keys = {"name",     "host",    "executor",
                                                 "realtime", "respawn", "components"};
const std::vector<std::string> respawn_kinds = {"never", "on_failure", "always"};

std::optional<RespawnPolicy> read_respawn(const FileReader& reader, const YAML::Node& node,
                                          const std::string& what) {
  RespawnPolicy policy;
  if (!node.IsMap()) {
    auto kind = reader.choice(node, what, respawn_kinds);
    if (!kind) return std::nullopt;
    policy.kind = static_cast<RespawnPolicy::Kind>(*kind);
    return policy;
  }
  bool ok = true;
  for (const auto& e : map_entries(reader, node, what, {"policy", "max_restarts", "backoff_s"})) {
    const std::string field = what + " '" + e.key + "'";
    if (e.key == "policy") {
      auto kind = reader.choice(e.value, field, respawn_kinds);
      if (kind) policy.kind = static_cast<RespawnPolicy::Kind>(*kind);
      ok = ok && kind.has_value();
    } else if (e.key == "max_restarts") {
      auto n = reader.integer(e.value, field, 0, 1000000);
      if (n) policy.max_restarts = static_cast<int>(*n);
      ok = ok && n.has_value();
    } else if (e.key == "backoff_s") {
      auto s = reader.number(e.value, field, 0.0, 3600.0);
      if (s) policy.backoff_s = *s;
      ok = ok && s.has_value();
    }
  }
  if (!ok) return std::nullopt;
  return policy;
}

/// `realtime: {sched: fifo, priority: 80, cpus: [2, 3], lock_memory: true}`.
std::optional<RealtimeSpec> read_realtime(const FileReader& reader, const YAML::Node& node,
                                          const std::string& what) {
  RealtimeSpec rt;
  bool ok = node.IsMap();
  const auto entries =
      map_entries(reader, node, what, {"sched", "priority", "cpus", "lock_memory"});
  const Entry* priority_entry = nullptr;
  for (const auto& e : entries) {
    const std::string field = what + " '" + e.key + "'";
    if (e.key == "sched") {
      auto i = reader.choice(e.value, field, {"other", "fifo", "rr"});
      if (i) rt.policy = static_cast<RealtimeSpec::Policy>(*i);
      ok = ok && i.has_value();
    } else if (e.key == "priority") {
      priority_entry = &e;
      auto n = reader.integer(e.value, field, 1, 99);
      if (n) rt.priority = static_cast<int>(*n);
      ok = ok && n.has_value();
    } else if (e.key == "cpus") {
      if (!e.value.IsSequence() || e.value.size() == 0) {
        reader.error(e.value, field + ": expected a non-empty list of CPU numbers, got " +
                                  node_kind(e.value));
        ok = false;
        continue;
      }
      for (const auto& item : e.value) {
        auto cpu = reader.integer(item, field, 0, 1023);
        if (!cpu) {
          ok = false;
        } else if (std::find(rt.cpus.begin(), rt.cpus.end(), *cpu) != rt.cpus.end()) {
          reader.error(item, field + ": CPU " + std::to_string(*cpu) + " listed twice");
          ok = false;
        } else {
          rt.cpus.push_back(static_cast<int>(*cpu));
        }
      }
    } else if (e.key == "lock_memory") {
      auto i = reader.choice(e.value, field, {"false", "true"});
      if (i) rt.lock_memory = *i == 1;
      ok = ok && i.has_value();
    }
  }
  if (!ok) return std::nullopt;
  const bool realtime_policy = rt.policy != RealtimeSpec::Policy::other;
  if (realtime_policy && priority_entry == nullptr) {
    reader.error(node, what + ": sched fifo and rr need a 'priority' (1-99)");
    return std::nullopt;
  }
  if (!realtime_policy && priority_entry != nullptr) {
    reader.error(priority_entry->value,
                 what + " 'priority': needs sched fifo or rr (SCHED_OTHER has no priority)");
    return std::nullopt;
  }
  return rt;
}

void read_container(LoadState& state, const FileReader& reader, const YAML::Node& node) {
  const auto entries = map_entries(reader, node, "container", container_keys);
  if (!node.IsMap()) return;
  ContainerSpec container;
  container.where = reader.at(node);
  std::string what = "container";
  const Entry* name_entry = find_entry(entries, "name");
  if (name_entry == nullptr) {
    reader.error(node, "container: missing required key 'name'");
    state.unnamed_container = true;
  } else if (auto name = reader.string(name_entry->value, "container 'name'")) {
    container.name = *name;
    container.where = reader.at(name_entry->value);
    what = "container '" + *name + "'";
    if (!is_identifier(*name)) {
      reader.error(name_entry->value,
                   "container 'name': expected letters, digits and '_' (not "
                   "starting with a digit), got '" +
                       *name + "'");
      state.unnamed_container = true;
    } else if (auto [it, inserted] = state.container_names.emplace(*name, container.where);
               !inserted) {
      reader.error(name_entry->value, "container 'name': duplicate container name '" + *name +
                                          "' (first defined at " + it->second.str() + ")");
    }
  } else {
    state.unnamed_container = true;
  }
  for (const auto& e : entries) {
    const std::string field = what + " '" + e.key + "'";
    if (e.key == "host") {
      if (auto host = reader.string(e.value, field)) container.host = *host;
    } else if (e.key == "executor") {
      if (auto i = reader.choice(e.value, field, {"single_threaded", "thread_per_component"})) {
        container.executor =
            *i == 0 ? ExecutorKind::single_threaded : ExecutorKind::thread_per_component;
      }
    } else if (e.key == "realtime") {
      if (auto rt = read_realtime(reader, e.value, field)) container.realtime = *rt;
    } else if (e.key == "respawn") {
      if (auto policy = read_respawn(reader, e.value, field)) container.respawn = *policy;
    } else if (e.key == "components") {
      if (!e.value.IsSequence() || e.value.size() == 0) {
        reader.error(e.value, field + ": expected a non-empty list of components, got " +
                                  node_kind(e.value));
        continue;
      }
      for (const auto& item : e.value) {
        if (auto c = read_component(state, reader, item, container.name))
          container.components.push_back(std::move(*c));
      }
    }
  }
  if (find_entry(entries, "components") == nullptr) {
    reader.error(node, what + ": missing required key 'components'");
  }
  state.graph.containers.push_back(std::move(container));
}

/// Why a writer offering `pub` cannot serve a reader requesting `sub`, or "".
std::string qos_incompatibility(const runtime::QosProfile& pub, const runtime::QosProfile& sub) {
  if (sub.reliability == runtime::Reliability::reliable &&
      pub.reliability == runtime::Reliability::best_effort) {
    return "a reliable reader needs a reliable writer";
  }
  if (sub.durability == runtime::Durability::transient_local &&
      pub.durability == runtime::Durability::volatile_) {
    return "a transient_local reader needs a transient_local writer";
  }
  if (sub.deadline && (!pub.deadline || *pub.deadline > *sub.deadline)) {
    return "the reader's deadline is shorter than the writer's";
  }
  return "";
}

std::string describe(const Endpoint& ep) {
  return "component '" + ep.component + "' port '" + ep.port + "' " +
         (ep.publisher ? "publishes " : "subscribes to ") + "'" + ep.topic + "' as " +
         runtime::to_ros_type_name(ep.dds_type);
}

}  // namespace

void read_containers(LoadState& state, const FileReader& reader, const YAML::Node& node) {
  if (!node.IsSequence()) {
    reader.error(node, "'containers': expected a list of containers, got " + node_kind(node));
    return;
  }
  for (const auto& item : node) read_container(state, reader, item);
}

void check_topics(LoadState& state) {
  // 1. Types. The reference type of a topic is its first publisher's (or, with no
  // publisher in the graph, its first subscriber's); every endpoint that differs is one error.
  std::map<std::string, const Endpoint*> reference;
  for (const auto& ep : state.endpoints) {
    if (ep.publisher) reference.emplace(ep.topic, &ep);
  }
  for (const auto& ep : state.endpoints) reference.emplace(ep.topic, &ep);
  for (const auto& ep : state.endpoints) {
    const Endpoint* ref = reference.at(ep.topic);
    if (ref == &ep || ref->dds_type == ep.dds_type) continue;
    std::string message = ep.publisher && ref->publisher
                              ? "two publishers of one topic with different types: "
                              : "topic type mismatch: ";
    message += describe(ep) + ", but " + describe(*ref) + " (at " + ref->where.str() + ")";
    state.diags.error(ep.where, message);
  }
  // 2. QoS across processes (DDS request/offer rules). Inside one container samples are
  // handed over directly, so only publishers in other containers matter.
  for (const auto& sub : state.endpoints) {
    if (sub.publisher) continue;
    for (const auto& pub : state.endpoints) {
      if (!pub.publisher || pub.topic != sub.topic || pub.dds_type != sub.dds_type ||
          pub.container == sub.container) {
        continue;
      }
      const std::string problem = qos_incompatibility(pub.qos, sub.qos);
      if (problem.empty()) continue;
      state.diags.error(sub.qos_where,
                        "incompatible QoS: component '" + sub.component + "' port '" + sub.port +
                            "' (container '" + sub.container + "') subscribes to '" + sub.topic +
                            "' with " + sub.qos.describe() + ", but component '" + pub.component +
                            "' (container '" + pub.container + "', at " + pub.where.str() +
                            ") publishes with " + pub.qos.describe() + ": " + problem +
                            "; DDS will not deliver between them (set 'qos' on either port)");
      break;  // one error per subscriber
    }
  }
}

}  // namespace detail

std::string port_topic(const Graph& graph, const ComponentInstance& component,
                       const runtime::PortSpec& port) {
  auto it = component.remaps.find(port.name);
  return runtime::resolve_topic_name(
      graph.ns, it != component.remaps.end() ? it->second : port.default_topic);
}

}  // namespace avs::graph
