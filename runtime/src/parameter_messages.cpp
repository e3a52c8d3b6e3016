// ParamValue / ParamSpec <-> rcl_interfaces messages, and the parameter service topic names.
#include "avs/runtime/parameter_messages.hpp"

#include <cmath>
#include <limits>

#include "avs/runtime/sample.hpp"

namespace avs::runtime {

RosParameterType ros_parameter_type(ParamType type) {
  switch (type) {
    case ParamType::boolean:
      return RosParameterType::boolean;
    case ParamType::integer:
      return RosParameterType::integer;
    case ParamType::real:
      return RosParameterType::real;
    case ParamType::string:
      return RosParameterType::string;
    case ParamType::real_list:
      return RosParameterType::real_array;
  }
  return RosParameterType::not_set;
}

std::optional<ParamType> param_type(RosParameterType type) {
  switch (type) {
    case RosParameterType::boolean:
      return ParamType::boolean;
    case RosParameterType::integer:
      return ParamType::integer;
    case RosParameterType::real:
      return ParamType::real;
    case RosParameterType::string:
      return ParamType::string;
    case RosParameterType::real_array:
    case RosParameterType::integer_array:
      return ParamType::real_list;
    default:
      return std::nullopt;
  }
}

std::string to_string(RosParameterType type) {
  static const char* const names[] = {
      "not set",    "boolean",       "integer",       "double",       "string",
      "byte array", "boolean array", "integer array", "double array", "string array"};
  const auto i = static_cast<std::size_t>(type);
  return i < std::size(names) ? names[i] : "unknown type " + std::to_string(i);
}

void to_message(const ParamValue& value, msgs::rcl_interfaces::ParameterValue& out) {
  out.type = static_cast<std::uint8_t>(ros_parameter_type(type_of(value)));
  if (const auto* b = std::get_if<bool>(&value)) out.bool_value = *b;
  if (const auto* i = std::get_if<std::int64_t>(&value)) out.integer_value = *i;
  if (const auto* d = std::get_if<double>(&value)) out.double_value = *d;
  if (const auto* s = std::get_if<std::string>(&value)) set_string(out.string_value, *s);
  if (const auto* list = std::get_if<std::vector<double>>(&value)) {
    resize_sequence(out.double_array_value, static_cast<std::uint32_t>(list->size()));
    for (std::size_t k = 0; k < list->size(); ++k) out.double_array_value._buffer[k] = (*list)[k];
  }
}

std::optional<ParamValue> from_message(const msgs::rcl_interfaces::ParameterValue& value) {
  switch (static_cast<RosParameterType>(value.type)) {
    case RosParameterType::boolean:
      return ParamValue{value.bool_value};
    case RosParameterType::integer:
      return ParamValue{static_cast<std::int64_t>(value.integer_value)};
    case RosParameterType::real:
      return ParamValue{value.double_value};
    case RosParameterType::string:
      return ParamValue{std::string(get_string(value.string_value))};
    case RosParameterType::real_array: {
      const auto items = as_span(value.double_array_value);
      return ParamValue{std::vector<double>(items.begin(), items.end())};
    }
    case RosParameterType::integer_array: {
      std::vector<double> list;
      for (const auto i : as_span(value.integer_array_value))
        list.push_back(static_cast<double>(i));
      return ParamValue{std::move(list)};
    }
    default:
      return std::nullopt;
  }
}

void to_descriptor(const ParamSpec& spec, msgs::rcl_interfaces::ParameterDescriptor& out) {
  set_string(out.name, spec.name);
  out.type = static_cast<std::uint8_t>(ros_parameter_type(spec.type));
  set_string(out.description, spec.description + (spec.unit.empty() ? "" : " [" + spec.unit + "]"));
  out.read_only = !spec.dynamic;
  out.dynamic_typing = false;
  std::string constraints;
  if (spec.type == ParamType::integer && (spec.min || spec.max)) {
    resize_sequence(out.integer_range, 1);
    auto& r = out.integer_range._buffer[0];
    r.from_value = spec.min ? static_cast<std::int64_t>(std::ceil(*spec.min))
                            : std::numeric_limits<std::int64_t>::min();
    r.to_value = spec.max ? static_cast<std::int64_t>(std::floor(*spec.max))
                          : std::numeric_limits<std::int64_t>::max();
    r.step = 0;
  } else if (spec.type == ParamType::real && (spec.min || spec.max)) {
    resize_sequence(out.floating_point_range, 1);
    auto& r = out.floating_point_range._buffer[0];
    r.from_value = spec.min.value_or(-std::numeric_limits<double>::infinity());
    r.to_value = spec.max.value_or(std::numeric_limits<double>::infinity());
    r.step = 0;
  } else if (spec.type == ParamType::real_list && (spec.min || spec.max)) {
    constraints = "each element" + range_text(spec.min, spec.max) + "; ";
  }
  if (!spec.choices.empty()) {
    constraints += "one of";
    for (std::size_t i = 0; i < spec.choices.size(); ++i) {
      constraints += (i ? ", '" : " '") + spec.choices[i] + "'";
    }
    constraints += "; ";
  }
  constraints += spec.dynamic
                     ? "dynamic: changeable while the graph runs"
                     : "read when the component starts: change it in the graph and restart";
  set_string(out.additional_constraints, constraints);
}

std::string parameter_request_topic(std::string_view node, std::string_view service) {
  return "rq" + std::string(node) + "/" + std::string(service) + "Request";
}

std::string parameter_reply_topic(std::string_view node, std::string_view service) {
  return "rr" + std::string(node) + "/" + std::string(service) + "Reply";
}

std::string parameter_service_node(std::string_view dds_topic) {
  for (const char* service : kParameterServices) {
    for (const auto& [prefix, suffix] :
         {std::pair<std::string, std::string>{"rq/", std::string("/") + service + "Request"},
          std::pair<std::string, std::string>{"rr/", std::string("/") + service + "Reply"}}) {
      if (dds_topic.size() > prefix.size() + suffix.size() &&
          dds_topic.substr(0, prefix.size()) == prefix &&
          dds_topic.substr(dds_topic.size() - suffix.size()) == suffix) {
        return std::string(dds_topic.substr(2, dds_topic.size() - 2 - suffix.size()));
      }
    }
  }
  return {};
}

QosProfile service_qos() {
  return QosProfile{};  // reliable, keep last 10, volatile
}

QosProfile parameter_events_qos() {
  QosProfile q;
  q.depth = 1000;
  return q;
}

}  // namespace avs::runtime
