// Reading one component entry: type, name, typed parameters, remaps and QoS overrides,
// each checked against the component's registered spec.

#include "avs/runtime/component.hpp"
#include "avs/runtime/error.hpp"
#include "avs/runtime/topic_name.hpp"
#include "components.hpp"

namespace avs::graph::detail {
namespace {

using runtime::ParamSpec;
using runtime::ParamType;
using runtime::ParamValue;

const std::vector<std::string> component_keys = {"type", "name", "parameters", "remap", "qos"};

/// What `spec` expects, as check() words it ("expected a number in [0, 1] m").
std::string expectation(const ParamSpec& spec) {
  const ParamValue wrong =
      spec.type == ParamType::real_list ? ParamValue{false} : ParamValue{std::vector<double>{}};
  std::string text = spec.check(wrong);
  const auto cut = text.rfind(", got ");
  return cut == std::string::npos ? text : text.substr(0, cut);
}

/// Reads a list of numbers from a YAML list, or from a scalar like "[1, 2]" (as an
/// argument substitution gives). Errors are reported with `what`.
std::optional<ParamValue> read_list(const FileReader& reader, const ParamSpec& spec,
                                    const YAML::Node& node, const std::string& what) {
  YAML::Node list = node;
  if (node.IsScalar()) {
    auto text = reader.string(node, what);
    if (!text) return std::nullopt;
    try {
      list.reset(YAML::Load(*text));  // reset: operator= would write into `node`
    } catch (const YAML::Exception&) {
      list.reset(YAML::Node(*text));
    }
    if (!list.IsSequence()) {
      reader.error(node, what + ": " + expectation(spec) + ", got '" + *text + "'");
      return std::nullopt;
    }
  }
  if (!list.IsSequence()) {
    reader.error(node, what + ": " + expectation(spec) + ", got " + node_kind(node));
    return std::nullopt;
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < list.size(); ++i) {
    // Elements of a list that came from one substituted scalar have no marks of their own.
    const YAML::Node item = node.IsSequence() ? node[i] : node;
    if (!list[i].IsScalar()) {
      reader.error(item, what + ": " + expectation(spec) + ", got " + node_kind(list[i]) +
                             " at index " + std::to_string(i));
      return std::nullopt;
    }
    auto text = node.IsSequence() ? reader.string(list[i], what) : list[i].Scalar();
    if (!text) return std::nullopt;
    const ParamValue v = runtime::parse_param_text(ParamType::real, *text);
    if (!std::holds_alternative<double>(v)) {
      reader.error(item, what + ": " + expectation(spec) + ", got '" + *text + "' at index " +
                             std::to_string(i));
      return std::nullopt;
    }
    values.push_back(std::get<double>(v));
  }
  return ParamValue{std::move(values)};
}

/// The typed value of parameter `spec` written as `node`, or nullopt (error reported).
std::optional<ParamValue> read_param(const FileReader& reader, const ParamSpec& spec,
                                     const YAML::Node& node, const std::string& what) {
  std::optional<ParamValue> value;
  if (spec.type == ParamType::real_list) {
    value = read_list(reader, spec, node, what);
    if (!value) return std::nullopt;
  } else {
    if (node.IsSequence() || node.IsMap()) {
      reader.error(node, what + ": " + expectation(spec) + ", got " + node_kind(node));
      return std::nullopt;
    }
    auto text = reader.string(node, what);
    if (!text) return std::nullopt;
    value = runtime::parse_param_text(spec.type, *text);
  }
  if (const std::string problem = spec.check(*value); !problem.empty()) {
    reader.error(node, what + ": " + problem);
    return std::nullopt;
  }
  return value;
}

std::string port_list(const runtime::ComponentSpec& spec) {
  std::string out;
  auto add = [&out](const runtime::PortSpec& p, const char* dir) {
    if (!out.empty()) out += ", ";
    out += "'" + p.name + "' (" + dir + " " + runtime::to_ros_type_name(p.dds_type) + ")";
  };
  for (const auto& p : spec.publishes) add(p, "publishes");
  for (const auto& p : spec.subscribes) add(p, "subscribes");
  return out.empty() ? "none" : out;
}

std::vector<std::string> port_names(const runtime::ComponentSpec& spec) {
  std::vector<std::string> names;
  for (const auto& p : spec.publishes) names.push_back(p.name);
  for (const auto& p : spec.subscribes) names.push_back(p.name);
  return names;
}

/// The port named by a remap/qos key, or nullptr (error reported).
const runtime::PortSpec* find_port(const FileReader& reader, const runtime::ComponentSpec& spec,
                                   const Entry& e, const std::string& what) {
  const runtime::PortSpec* port = spec.find_port(e.key);
  if (port == nullptr) {
    reader.error(e.key_node, what + ": unknown port '" + e.key + "'" +
                                 did_you_mean(e.key, port_names(spec)) + "; ports of '" +
                                 spec.type + "': " + port_list(spec));
  }
  return port;
}

std::optional<runtime::QosProfile> read_qos(const FileReader& reader, const runtime::PortSpec& port,
                                            const YAML::Node& node, const std::string& what) {
  static const std::vector<std::string> profile_names = {"default", "sensor_data", "reliable",
                                                         "transient_local", "clock"};
  if (!node.IsMap()) {
    auto name = reader.string(node, what);
    if (!name) return std::nullopt;
    auto profile = runtime::QosProfile::named(*name);
    if (!profile) {
      reader.error(node, what + ": unknown QoS profile '" + *name + "'" +
                             did_you_mean(*name, profile_names) + "; expected one of " +
                             join_quoted(profile_names) +
                             " or a mapping {reliability, depth, durability, deadline_ms}");
    }
    return profile;
  }
  runtime::QosProfile qos = port.qos;  // a mapping changes the port's declared QoS
  bool ok = true;
  for (const auto& e :
       map_entries(reader, node, what, {"reliability", "depth", "durability", "deadline_ms"})) {
    const std::string field = what + " '" + e.key + "'";
    if (e.key == "reliability") {
      auto i = reader.choice(e.value, field, {"reliable", "best_effort"});
      if (i)
        qos.reliability =
            *i == 0 ? runtime::Reliability::reliable : runtime::Reliability::best_effort;
      ok = ok && i.has_value();
    } else if (e.key == "durability") {
      auto i = reader.choice(e.value, field, {"volatile", "transient_local"});
      if (i)
        qos.durability =
            *i == 0 ? runtime::Durability::volatile_ : runtime::Durability::transient_local;
      ok = ok && i.has_value();
    } else if (e.key == "depth") {
      auto d = reader.integer(e.value, field, 1, 100000);
      if (d) qos.depth = static_cast<std::uint32_t>(*d);
      ok = ok && d.has_value();
    } else if (e.key == "deadline_ms") {
      auto ms = reader.number(e.value, field, 0.001, 3.6e6);
      if (ms) qos.deadline = runtime::Duration(static_cast<std::int64_t>(*ms * 1e6));
      ok = ok && ms.has_value();
    }
  }
  if (!ok) return std::nullopt;
  return qos;
}

std::string known_types_hint(std::string_view type) {
  std::vector<std::string> known;
  for (const auto* c : runtime::ComponentRegistry::instance().all()) known.push_back(c->spec.type);
  if (known.empty()) return " (no component types are linked into this program)";
  std::string hint = did_you_mean(type, known);
  if (known.size() <= 12) hint += "; known types: " + join_quoted(known);
  return hint;
}

}  // namespace

std::optional<ComponentInstance> read_component(LoadState& state, const FileReader& reader,
                                                const YAML::Node& node,
                                                const std::string& container) {
  const auto entries = map_entries(reader, node, "component", component_keys);
  if (!node.IsMap()) return std::nullopt;
  ComponentInstance instance;
  instance.where = reader.at(node);

  // 1. Name and type, both required.
  const Entry* name_entry = find_entry(entries, "name");
  const Entry* type_entry = find_entry(entries, "type");
  std::string what = "component";
  bool ok = true;
  if (name_entry == nullptr) {
    reader.error(node, "component: missing required key 'name'");
    ok = false;
  } else if (auto name = reader.string(name_entry->value, "component 'name'")) {
    instance.name = *name;
    what = "component '" + *name + "'";
    instance.where = reader.at(name_entry->value);
    if (!is_identifier(*name)) {
      reader.error(name_entry->value,
                   "component 'name': expected letters, digits and '_' "
                   "(not starting with a digit), got '" +
                       *name + "'");
      ok = false;
    } else if (auto [it, inserted] = state.component_names.emplace(*name, instance.where);
               !inserted) {
      reader.error(name_entry->value, "component 'name': duplicate component name '" + *name +
                                          "' (first defined at " + it->second.str() + ")");
      ok = false;
    }
  } else {
    ok = false;
  }
  if (type_entry == nullptr) {
    reader.error(node, what + ": missing required key 'type'");
    return std::nullopt;
  }
  auto type = reader.string(type_entry->value, what + " 'type'");
  if (!type) return std::nullopt;
  instance.type = *type;
  const auto* registered = runtime::ComponentRegistry::instance().find(*type);
  if (registered == nullptr) {
    reader.error(type_entry->value, what + " 'type': unknown component type '" + *type + "'" +
                                        known_types_hint(*type));
    return std::nullopt;
  }
  const runtime::ComponentSpec& spec = registered->spec;
  what += " (" + spec.type + ")";

  // 2. Parameters: each checked against its declaration, then defaults filled in.
  if (const Entry* params = find_entry(entries, "parameters")) {
    for (const auto& e : map_entries(reader, params->value, what + " 'parameters'", {})) {
      const ParamSpec* p = spec.find_parameter(e.key);
      if (p == nullptr) {
        std::vector<std::string> declared;
        for (const auto& d : spec.parameters) declared.push_back(d.name);
        reader.error(e.key_node,
                     what + ": unknown parameter '" + e.key + "'" + did_you_mean(e.key, declared) +
                         "; declared: " + (declared.empty() ? "none" : join_quoted(declared)));
        ok = false;
        continue;
      }
      auto value = read_param(reader, *p, e.value, what + " parameter '" + e.key + "'");
      if (value) {
        instance.parameters.set(p->name, std::move(*value));
      } else {
        ok = false;
      }
    }
  }
  for (const auto& p : spec.parameters) {
    if (!instance.parameters.contains(p.name)) instance.parameters.set(p.name, p.default_value);
  }

  // 3. Remaps: port -> topic name, valid under the graph's namespace.
  std::map<std::string, SourceLocation> remap_where;
  if (const Entry* remap = find_entry(entries, "remap")) {
    for (const auto& e : map_entries(reader, remap->value, what + " 'remap'", {})) {
      if (find_port(reader, spec, e, what + " 'remap'") == nullptr) {
        ok = false;
        continue;
      }
      auto topic = reader.string(e.value, what + " remap '" + e.key + "'");
      if (!topic) {
        ok = false;
        continue;
      }
      try {
        runtime::resolve_topic_name(state.graph.ns, *topic);
        instance.remaps[e.key] = *topic;
        remap_where[e.key] = reader.at(e.value);
      } catch (const runtime::Error& err) {
        reader.error(e.value, what + " remap '" + e.key + "': " + err.what());
        ok = false;
      }
    }
  }

  // 4. QoS overrides: a named profile or single policies.
  std::map<std::string, SourceLocation> qos_where;
  if (const Entry* qos = find_entry(entries, "qos")) {
    for (const auto& e : map_entries(reader, qos->value, what + " 'qos'", {})) {
      const runtime::PortSpec* port = find_port(reader, spec, e, what + " 'qos'");
      if (port == nullptr) {
        ok = false;
        continue;
      }
      if (auto profile = read_qos(reader, *port, e.value, what + " qos '" + e.key + "'")) {
        instance.qos[e.key] = *profile;
        qos_where[e.key] = reader.at(e.value);
      } else {
        ok = false;
      }
    }
  }

  // 5. Endpoints for the graph-wide type and QoS checks.
  auto add_endpoints = [&](const std::vector<runtime::PortSpec>& ports, bool publisher) {
    for (const auto& port : ports) {
      auto remapped = instance.remaps.find(port.name);
      const std::string& topic =
          remapped != instance.remaps.end() ? remapped->second : port.default_topic;
      try {
        Endpoint ep;
        ep.topic = runtime::resolve_topic_name(state.graph.ns, topic);
        ep.dds_type = port.dds_type;
        ep.publisher = publisher;
        ep.component = instance.name;
        ep.port = port.name;
        ep.container = container;
        ep.where = instance.where;
        if (auto w = remap_where.find(port.name); w != remap_where.end()) ep.where = w->second;
        ep.qos = port.qos;
        ep.qos_where = ep.where;
        if (auto q = instance.qos.find(port.name); q != instance.qos.end()) {
          ep.qos = q->second;
          ep.qos_where = qos_where.at(port.name);
        }
        state.endpoints.push_back(std::move(ep));
      } catch (const runtime::Error& err) {
        reader.error(type_entry->value,
                     what + " port '" + port.name + "' default topic: " + err.what());
        ok = false;
      }
    }
  };
  add_endpoints(spec.publishes, true);
  add_endpoints(spec.subscribes, false);
  if (!ok) return std::nullopt;
  return instance;
}

}  // namespace avs::graph::detail
