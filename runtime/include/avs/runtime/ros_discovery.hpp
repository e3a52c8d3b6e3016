// ROS 2 nodes over plain DDS: the ros_discovery_info topic (rmw_dds_common's
// ParticipantEntitiesInfo, no "rt/" prefix, reliable, transient local, keep last 1) on which
// every ROS 2 participant says which nodes it holds and which readers and writers each node
// owns. A container publishes one for its components (`ros2 node list` shows them); `avs node`
// reads them (docs/operate.md).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "avs/runtime/dds.hpp"

namespace avs::runtime {

/// A DDS GUID (participant, reader or writer), as rmw_dds_common's Gid carries it.
using Gid = std::array<std::uint8_t, 16>;

Gid gid_of(dds_entity_t entity);

/// One ROS 2 node: namespace ("/" or "/rig"), name, the GUIDs of its readers and writers.
struct NodeEntities {
  std::string node_namespace;
  std::string node_name;
  std::vector<Gid> readers;
  std::vector<Gid> writers;
};

/// One participant's nodes (one sample of ros_discovery_info).
struct ParticipantNodes {
  Gid participant{};
  std::vector<NodeEntities> nodes;
};

inline constexpr const char* kRosDiscoveryTopic = "ros_discovery_info";
/// The participant USER_DATA rmw_dds_common needs to take a participant's nodes into the ROS
/// graph (the security enclave; "/" without security).
inline constexpr const char* kRosParticipantUserData = "enclave=/;";

/// Publishes this participant's nodes on ros_discovery_info (latched for late joiners).
class RosDiscoveryWriter {
 public:
  explicit RosDiscoveryWriter(const dds::Participant& participant);
  void publish(const std::vector<NodeEntities>& nodes);

 private:
  const dds::Participant& participant_;
  dds::Topic topic_;
  dds::Writer writer_;
};

/// Every participant's latest ros_discovery_info that arrives within `wait` (ours left out).
std::vector<ParticipantNodes> read_ros_discovery(const dds::Participant& participant,
                                                 std::chrono::milliseconds wait);

}  // namespace avs::runtime
