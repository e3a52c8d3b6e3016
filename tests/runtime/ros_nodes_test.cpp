// Issue 18 section 3: a running graph's components are ROS 2 nodes. A plain DDS reader of
// ros_discovery_info (rmw_dds_common/msg/ParticipantEntitiesInfo) finds every component with
// the GUIDs of its readers and writers, and DDS discovery ties those to the component's topics;
// the participant carries the USER_DATA ROS 2 needs ("enclave=/;"); `avs node` reads the same.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <thread>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/parameter_messages.hpp"
#include "avs/runtime/qos.hpp"
#include "avs/runtime/ros_discovery.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/testing/lockstep_graph.hpp"
#include "avs/testing/test_domain.hpp"
#ifdef AVS_PROGRAM
#include "avs_program.hpp"
#endif

namespace avs::runtime {
namespace {

using Clock = std::chrono::steady_clock;

/// DDS topic name of every endpoint (reader or writer) the built-in topics show, by GUID.
std::map<Gid, std::string> endpoint_topics(const dds::Participant& participant) {
  std::map<Gid, std::string> out;
  for (const auto builtin :
       {DDS_BUILTIN_TOPIC_DCPSPUBLICATION, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION}) {
    dds::Entity reader(dds_create_reader(participant.get(), builtin, nullptr, nullptr));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    void* samples[1024] = {};
    dds_sample_info_t infos[1024];
    const int n = dds_read(reader.get(), samples, infos, 1024, 1024);
    for (int i = 0; i < n; ++i) {
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      Gid gid;
      std::copy(std::begin(ep->key.v), std::end(ep->key.v), gid.begin());
      out[gid] = ep->topic_name;
    }
    if (n > 0) dds_return_loan(reader.get(), samples, n);
  }
  return out;
}

/// USER_DATA of every remote participant, as text.
std::vector<std::string> participant_user_data(const dds::Participant& participant) {
  std::vector<std::string> out;
  dds::Entity reader(
      dds_create_reader(participant.get(), DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  void* samples[64] = {};
  dds_sample_info_t infos[64];
  const int n = dds_read(reader.get(), samples, infos, 64, 64);
  for (int i = 0; i < n; ++i) {
    const auto* p = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
    void* data = nullptr;
    std::size_t size = 0;
    if (p->qos != nullptr && dds_qget_userdata(p->qos, &data, &size) && data != nullptr) {
      out.emplace_back(static_cast<const char*>(data), size);
      dds_free(data);
    }
  }
  if (n > 0) dds_return_loan(reader.get(), samples, n);
  return out;
}

/// A reader or writer created the way rmw_cyclonedds creates a service client's endpoints:
/// the service QoS and `clientid=ID;` in USER_DATA (the same ID on the client's request writer
/// and reply reader).
dds::Entity client_endpoint(const dds::Participant& participant, const dds::Topic& topic,
                            bool writer, const std::string& id) {
  Qos qos(service_qos());
  const std::string user_data = "clientid=" + id + ";";
  dds_qset_userdata(qos.get(), user_data.data(), user_data.size());
  return dds::Entity(
      check_dds(writer ? dds_create_writer(participant.get(), topic.get(), qos.get(), nullptr)
                       : dds_create_reader(participant.get(), topic.get(), qos.get(), nullptr),
                "client endpoint on " + topic.name()));
}

/// Issue 18 section 1, `ros2 param` against an avs node: one ROS 2 process holds several
/// clients in one participant. A request from client A must not be answered as soon as some
/// other client's reply reader of that participant has matched (the reply would go out before
/// A's own reader exists and be lost to it): the service waits for the reader whose clientid
/// is the request writer's, as rmw_cyclonedds's services do.
TEST(RosNodes, ParameterReplyWaitsForTheReaderOfTheAskingClient) {
  namespace rcl = msgs::rcl_interfaces;
  avs::testing::BackgroundContainer graph(
      {"{type: test_talker, name: talker, parameters: {rate_hz: 100}}"}, 600.0,
      avs::testing::TestClock::wall);
  for (const auto& e : graph.run().load_errors) ADD_FAILURE() << e;
  ASSERT_NE(graph.run().container, nullptr);
  dds::Participant participant(avs::testing::test_domain());
  const QosProfile qos = service_qos();
  dds::Topic requests(participant, msg::TypeSupport<rcl::GetParameters_Request>::descriptor(),
                      parameter_request_topic("/talker", "get_parameters"), qos);
  dds::Topic replies(participant, msg::TypeSupport<rcl::GetParameters_Response>::descriptor(),
                     parameter_reply_topic("/talker", "get_parameters"), qos);
  // Client B's reply reader, then client A's request writer; A's reader comes later.
  const dds::Entity reader_b = client_endpoint(participant, replies, false, "0b.0b");
  const dds::Entity writer_a = client_endpoint(participant, requests, true, "0a.0a");
  for (const auto deadline = Clock::now() + std::chrono::seconds(20);;) {
    dds_publication_matched_status_t matched{};
    ASSERT_EQ(dds_get_publication_matched_status(writer_a.get(), &matched), DDS_RETCODE_OK);
    if (matched.current_count > 0) break;
    ASSERT_LT(Clock::now(), deadline) << "talker's get_parameters service never matched";
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  auto request = make_sample<rcl::GetParameters_Request>();
  request->client_guid = 0xa;
  request->sequence_number = 1;
  ASSERT_EQ(dds_write(writer_a.get(), request.get()), DDS_RETCODE_OK);
  // A moment for the service to take the request (a slow machine only makes this weaker).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const dds::Entity reader_a = client_endpoint(participant, replies, false, "0a.0a");
  bool answered = false;
  for (const auto deadline = Clock::now() + std::chrono::seconds(20);
       !answered && Clock::now() < deadline;) {
    auto reply = make_sample<rcl::GetParameters_Response>();
    void* buffers[1] = {reply.get()};
    dds_sample_info_t info;
    answered = dds_take(reader_a.get(), buffers, &info, 1, 1) > 0 && info.valid_data &&
               reply->client_guid == 0xa && reply->sequence_number == 1;
    if (!answered) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(answered) << "client A's reader never got the reply to A's request";
}

TEST(RosNodes, EveryComponentIsOnRosDiscoveryInfoWithItsTopics) {
  avs::testing::BackgroundContainer graph(
      {"{type: test_talker, name: talker, parameters: {rate_hz: 100}}",
       "{type: test_listener, name: listener}"},
      600.0, avs::testing::TestClock::wall);
  for (const auto& e : graph.run().load_errors) ADD_FAILURE() << e;
  ASSERT_NE(graph.run().container, nullptr);

  // 1. A plain DDS reader: the sample names both components.
  dds::Participant participant(avs::testing::test_domain());
  QosProfile qos;
  qos.depth = 1;
  qos.durability = Durability::transient_local;
  dds::Topic topic(participant,
                   msg::TypeSupport<msgs::rmw_dds_common::ParticipantEntitiesInfo>::descriptor(),
                   "ros_discovery_info", qos);
  dds::Reader reader(participant, topic, qos);
  auto info = make_sample<msgs::rmw_dds_common::ParticipantEntitiesInfo>();
  bool received = false;
  for (const auto deadline = Clock::now() + std::chrono::seconds(10);
       !received && Clock::now() < deadline;) {
    void* buffers[1] = {info.get()};
    dds_sample_info_t sample_info;
    received = dds_take(reader.get(), buffers, &sample_info, 1, 1) > 0 && sample_info.valid_data;
    if (!received) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(received) << "no ros_discovery_info sample";
  std::map<std::string, const msgs::rmw_dds_common::NodeEntitiesInfo*> nodes;
  for (const auto& node : as_span(info->node_entities_info_seq)) {
    EXPECT_STREQ(node.node_namespace, "/");
    nodes[node.node_name] = &node;
  }
  ASSERT_EQ(nodes.size(), 2u);
  ASSERT_TRUE(nodes.count("talker") && nodes.count("listener"));

  // 2. Their GUIDs are the readers and writers of their topics (and parameter services).
  const auto topics = endpoint_topics(participant);
  const auto topics_of = [&](const dds_sequence_rmw_dds_common_msg_dds__Gid_& gids) {
    std::set<std::string> names;
    for (const auto& g : as_span(gids)) {
      Gid gid;
      std::copy(std::begin(g.data), std::end(g.data), gid.begin());
      if (const auto it = topics.find(gid); it != topics.end()) names.insert(it->second);
    }
    return names;
  };
  const auto talker_writers = topics_of(nodes["talker"]->writer_gid_seq);
  EXPECT_TRUE(talker_writers.count("rt/chatter"));
  EXPECT_TRUE(talker_writers.count("rt/talker_count"));
  EXPECT_TRUE(talker_writers.count("rr/talker/get_parametersReply"));
  const auto listener_readers = topics_of(nodes["listener"]->reader_gid_seq);
  EXPECT_TRUE(listener_readers.count("rt/chatter"));
  EXPECT_TRUE(listener_readers.count("rq/listener/set_parametersRequest"));
  EXPECT_FALSE(topics_of(nodes["listener"]->writer_gid_seq).count("rt/chatter"));

  // 3. The USER_DATA that makes ROS 2 take the participant's nodes into its graph.
  const auto user_data = participant_user_data(participant);
  EXPECT_NE(std::find(user_data.begin(), user_data.end(), "enclave=/;"), user_data.end());

#ifdef AVS_PROGRAM
  // 4. `avs node list` and `avs node info` read the same.
  const auto dir =
      std::filesystem::temp_directory_path() / ("avs_ros_nodes_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  ASSERT_EQ(avs::testing::run_avs({"node", "list"}, dir / "out", dir / "err"), 0)
      << avs::testing::read_file(dir / "err");
  EXPECT_EQ(avs::testing::read_file(dir / "out"), "/listener\n/talker\n");
  ASSERT_EQ(avs::testing::run_avs({"node", "info", "talker"}, dir / "out", dir / "err"), 0)
      << avs::testing::read_file(dir / "err");
  const std::string talker = avs::testing::read_file(dir / "out");
  EXPECT_NE(talker.find("  Publishers:\n"), std::string::npos) << talker;
  EXPECT_NE(talker.find("    /chatter: std_msgs/msg/String\n"), std::string::npos) << talker;
  EXPECT_NE(talker.find("    /talker/set_parameters: rcl_interfaces/srv/SetParameters\n"),
            std::string::npos)
      << talker;
  std::filesystem::remove_all(dir);
#endif
  EXPECT_EQ(graph.stop(), 0);
}

}  // namespace
}  // namespace avs::runtime
