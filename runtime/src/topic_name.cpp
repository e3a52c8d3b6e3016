// ROS 2 topic names (design article 140, "topic and service name mapping") and the DDS
// names rmw_cyclonedds uses for them: see ../shared/reference/ros2-messages-and-mcap.md §4a.
#include "avs/runtime/topic_name.hpp"

#include "avs/runtime/error.hpp"

namespace avs::runtime {
namespace {

constexpr std::size_t max_dds_topic_length = 256;  // prefix "rt" included

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

/// Empty when `name` is a valid ROS name (absolute or relative); otherwise why not.
/// Rules: only [A-Za-z0-9_/], no empty token ("//"), no trailing '/', no token
/// starting with a digit.
std::string name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name == "/") return {};
  if (name.back() == '/') return "ends with '/'";
  bool token_start = true;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '/') {
      if (i != 0 && token_start) return "contains '//'";
      token_start = true;
      continue;
    }
    if (!is_name_char(c)) {
      return "contains '" + std::string(1, c) + "' (allowed: letters, digits, '_' and '/')";
    }
    if (token_start && c >= '0' && c <= '9') return "has a part starting with a digit";
    token_start = false;
  }
  return {};
}

}  // namespace

std::string resolve_topic_name(std::string_view ns, std::string_view name) {
  if (auto why = name_problem(name); !why.empty()) {
    throw Error("invalid topic name '" + std::string(name) + "': " + why);
  }
  if (name == "/") throw Error("invalid topic name '/': names a namespace, not a topic");
  if (auto why = name_problem(ns); !why.empty()) {
    throw Error("invalid namespace '" + std::string(ns) + "': " + why);
  }
  if (ns.front() != '/')
    throw Error("invalid namespace '" + std::string(ns) + "': must start with '/'");
  std::string out;
  if (name.front() == '/') {
    out = std::string(name);
  } else if (ns == "/") {
    out = "/" + std::string(name);
  } else {
    out = std::string(ns) + "/" + std::string(name);
  }
  if (out.size() + 2 > max_dds_topic_length) {
    throw Error("topic name '" + out + "' is too long (DDS name 'rt" + out.substr(0, 20) +
                "...' must be at most 256 characters)");
  }
  return out;
}

std::string to_dds_topic_name(std::string_view ros_name) {
  if (ros_name.empty() || ros_name.front() != '/') {
    throw Error("to_dds_topic_name: '" + std::string(ros_name) + "' is not a fully qualified name");
  }
  return "rt" + std::string(ros_name);
}

std::string from_dds_topic_name(std::string_view dds_name) {
  // rmw_cyclonedds strips the prefix only when it is followed by '/'.
  if (dds_name.size() > 2 && dds_name.substr(0, 3) == "rt/") return std::string(dds_name.substr(2));
  return std::string(dds_name);
}

std::string to_ros_type_name(std::string_view dds_type_name) {
  // Demangled only if it ends in '_' and contains "dds_::" (rmw_cyclonedds demangle.cpp).
  constexpr std::string_view marker = "dds_::";
  const auto pos = dds_type_name.find(marker);
  if (dds_type_name.empty() || dds_type_name.back() != '_' || pos == std::string_view::npos) {
    return std::string(dds_type_name);
  }
  std::string out;
  const std::string_view prefix = dds_type_name.substr(0, pos);
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (prefix.compare(i, 2, "::") == 0) {
      out += '/';
      ++i;
    } else {
      out += prefix[i];
    }
  }
  const std::string_view type = dds_type_name.substr(pos + marker.size());
  out += type.substr(0, type.size() - 1);
  return out;
}

}  // namespace avs::runtime
