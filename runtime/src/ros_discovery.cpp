// ros_discovery_info: write this participant's nodes, read everyone's.
#include "avs/runtime/ros_discovery.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <map>
#include <thread>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/sample.hpp"

namespace avs::runtime {

namespace rmw = msgs::rmw_dds_common;

namespace {

QosProfile discovery_qos() {
  QosProfile q;
  q.depth = 1;
  q.durability = Durability::transient_local;
  return q;
}

void copy_name(char (&out)[257], const std::string& name) {
  std::strncpy(out, name.c_str(), sizeof out - 1);
  out[sizeof out - 1] = '\0';
}

void fill(dds_sequence_rmw_dds_common_msg_dds__Gid_& out, const std::vector<Gid>& gids) {
  resize_sequence(out, static_cast<std::uint32_t>(gids.size()));
  for (std::size_t i = 0; i < gids.size(); ++i) {
    std::copy(gids[i].begin(), gids[i].end(), out._buffer[i].data);
  }
}

std::vector<Gid> gids(const dds_sequence_rmw_dds_common_msg_dds__Gid_& in) {
  std::vector<Gid> out;
  for (const auto& g : as_span(in)) {
    Gid gid;
    std::copy(std::begin(g.data), std::end(g.data), gid.begin());
    out.push_back(gid);
  }
  return out;
}

}  // namespace

Gid gid_of(dds_entity_t entity) {
  dds_guid_t guid{};
  check_dds(dds_get_guid(entity, &guid), "GUID of a DDS entity");
  Gid gid;
  std::copy(std::begin(guid.v), std::end(guid.v), gid.begin());
  return gid;
}

RosDiscoveryWriter::RosDiscoveryWriter(const dds::Participant& participant)
    : participant_(participant),
      topic_(participant, msg::TypeSupport<rmw::ParticipantEntitiesInfo>::descriptor(),
             kRosDiscoveryTopic, discovery_qos()),
      writer_(participant, topic_, discovery_qos()) {}

void RosDiscoveryWriter::publish(const std::vector<NodeEntities>& nodes) {
  auto info = make_sample<rmw::ParticipantEntitiesInfo>();
  const Gid own = gid_of(participant_.get());
  std::copy(own.begin(), own.end(), info->gid.data);
  resize_sequence(info->node_entities_info_seq, static_cast<std::uint32_t>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    auto& node = info->node_entities_info_seq._buffer[i];
    copy_name(node.node_namespace, nodes[i].node_namespace);
    copy_name(node.node_name, nodes[i].node_name);
    fill(node.reader_gid_seq, nodes[i].readers);
    fill(node.writer_gid_seq, nodes[i].writers);
  }
  writer_.write(info.get());
}

std::vector<ParticipantNodes> read_ros_discovery(const dds::Participant& participant,
                                                 std::chrono::milliseconds wait) {
  QosProfile qos = discovery_qos();
  qos.depth = 1000;  // one instance for every writer of the key-less topic: keep them all
  dds::Topic topic(participant, msg::TypeSupport<rmw::ParticipantEntitiesInfo>::descriptor(),
                   kRosDiscoveryTopic, qos);
  dds::Reader reader(participant, topic, qos);
  std::this_thread::sleep_for(wait);
  std::map<Gid, ParticipantNodes> latest;
  for (;;) {
    auto info = make_sample<rmw::ParticipantEntitiesInfo>();
    void* buffers[1] = {info.get()};
    dds_sample_info_t sample_info;
    if (dds_take(reader.get(), buffers, &sample_info, 1, 1) <= 0) break;
    if (!sample_info.valid_data) continue;
    ParticipantNodes p;
    std::copy(std::begin(info->gid.data), std::end(info->gid.data), p.participant.begin());
    for (const auto& node : as_span(info->node_entities_info_seq)) {
      p.nodes.push_back({node.node_namespace, node.node_name, gids(node.reader_gid_seq),
                         gids(node.writer_gid_seq)});
    }
    latest[p.participant] = std::move(p);
  }
  std::vector<ParticipantNodes> out;
  for (auto& [gid, p] : latest) out.push_back(std::move(p));
  return out;
}

}  // namespace avs::runtime
