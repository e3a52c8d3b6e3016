// The `offered_qos_profiles` channel metadata of ROS 2 MCAP files (what rosbag2 writes):
// a YAML list with one entry per publisher, enums as rmw's integers.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "avs/runtime/raw_topic.hpp"

namespace avs::bag {

/// rosbag2's YAML for a list of offered QoS profiles (history 1 = keep last, 2 = keep all;
/// reliability 1 = reliable, 2 = best effort; durability 1 = transient local, 2 = volatile;
/// liveliness 1 = automatic, 3 = manual by topic; infinite durations as
/// sec 2147483647, nsec 4294967295).
std::string offered_qos_yaml(const std::vector<runtime::dds::EndpointQos>& profiles);

/// Parses that YAML back. Throws runtime::Error naming the problem when it is not a list of
/// profiles; returns an empty list for an empty string.
std::vector<runtime::dds::EndpointQos> parse_offered_qos_yaml(std::string_view yaml);

/// The QoS to replay a topic with: the first recorded profile (ROS 2 tools do the same);
/// the "default" profile when none was stored.
runtime::dds::EndpointQos replay_qos(const std::vector<runtime::dds::EndpointQos>& profiles);

}  // namespace avs::bag
