// ROS 2 topic names and their DDS form: "/depth" in namespace "/" is DDS topic "rt/depth".
#pragma once

#include <string>
#include <string_view>

namespace avs::runtime {

/// Resolves `name` against `ns` ("/avs"): absolute names stay, relative ones get the
/// namespace. Throws Error on an invalid name (empty, "//", characters outside [A-Za-z0-9_/]).
std::string resolve_topic_name(std::string_view ns, std::string_view name);

/// "/depth" -> "rt/depth" (ROS 2's rule: prefix "rt" before the fully qualified name).
std::string to_dds_topic_name(std::string_view ros_name);

/// "rt/depth" -> "/depth"; other names (no "rt/" prefix) are returned unchanged.
std::string from_dds_topic_name(std::string_view dds_name);

/// "sensor_msgs::msg::dds_::Image_" -> "sensor_msgs/msg/Image" (ROS 2's demangling).
std::string to_ros_type_name(std::string_view dds_type_name);

}  // namespace avs::runtime
