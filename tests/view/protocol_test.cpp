// The Foxglove protocol encoding and request parsing of libs/view, without sockets.
#include "avs/view/protocol.hpp"

#include <gtest/gtest.h>

namespace avs::view {
namespace {

TEST(ViewProtocol, AdvertiseCarriesTopicSchemaAndEncodings) {
  Channel c;
  c.id = 3;
  c.topic = "/depth/image";
  c.schema_name = "sensor_msgs/msg/Image";
  c.schema = "std_msgs/Header header\nuint32 height\n";
  const std::string json = advertise_json(std::span<const Channel>(&c, 1));
  EXPECT_EQ(json,
            R"({"channels":[{"encoding":"cdr","id":3,"schema":"std_msgs/Header header\nuint32 )"
            R"(height\n","schemaEncoding":"ros2msg","schemaName":"sensor_msgs/msg/Image",)"
            R"("topic":"/depth/image"}],"op":"advertise"})");
}

TEST(ViewProtocol, ServerInfoStatusAndUnadvertise) {
  EXPECT_EQ(server_info_json("avs view", "42"),
            R"({"capabilities":[],"metadata":{},"name":"avs view","op":"serverInfo",)"
            R"("sessionId":"42","supportedEncodings":[]})");
  EXPECT_EQ(status_json(StatusLevel::error, "bad"), R"({"level":2,"message":"bad","op":"status"})");
  const ChannelId ids[] = {1, 7};
  EXPECT_EQ(unadvertise_json(ids), R"({"channelIds":[1,7],"op":"unadvertise"})");
}

TEST(ViewProtocol, MessageDataHeaderIsLittleEndian) {
  const auto h = message_data_header(0x01020304u, 0x1122334455667788ull);
  const std::array<std::uint8_t, 13> expected = {0x01, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77,
                                                 0x66, 0x55, 0x44, 0x33, 0x22, 0x11};
  EXPECT_EQ(h, expected);
}

TEST(ViewProtocol, ParsesSubscribeAndUnsubscribe) {
  const auto s = parse_client_message(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":5}]})");
  ASSERT_TRUE(std::holds_alternative<Subscribe>(s));
  const auto& items = std::get<Subscribe>(s).subscriptions;
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[1].id, 1u);
  EXPECT_EQ(items[1].channel, 5u);
  const auto u = parse_client_message(R"({"op":"unsubscribe","subscriptionIds":[0,1]})");
  ASSERT_TRUE(std::holds_alternative<Unsubscribe>(u));
  EXPECT_EQ(std::get<Unsubscribe>(u).ids, (std::vector<SubscriptionId>{0, 1}));
}

TEST(ViewProtocol, RejectsBadMessagesWithAReason) {
  const std::pair<const char*, const char*> cases[] = {
      {"not json", "not valid JSON"},
      {"[1,2]", "must be a JSON object"},
      {R"({"subscriptions":[]})", "missing string field \"op\""},
      {R"({"op":"setParameters","parameters":[]})", "\"setParameters\" is not supported"},
      {R"({"op":"subscribe"})", "\"subscriptions\" must be an array"},
      {R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":3}]})", "\"id\" must be"},
      {R"({"op":"subscribe","subscriptions":[{"id":1}]})", "missing \"channelId\""},
      {R"({"op":"unsubscribe","subscriptionIds":["a"]})", "must be integers"},
  };
  for (const auto& [text, reason] : cases) {
    const auto r = parse_client_message(text);
    ASSERT_TRUE(std::holds_alternative<Rejected>(r)) << text;
    EXPECT_NE(std::get<Rejected>(r).reason.find(reason), std::string::npos)
        << text << " -> " << std::get<Rejected>(r).reason;
  }
}

TEST(ViewProtocol, RequestTargetOptions) {
  const ClientOptions defaults{2.0};
  EXPECT_EQ(parse_request_target("/", defaults).options.max_rate_hz, 2.0);
  const auto t = parse_request_target("/?max_rate_hz=12.5", defaults);
  EXPECT_TRUE(t.error.empty());
  EXPECT_EQ(t.options.max_rate_hz, 12.5);
  EXPECT_NE(parse_request_target("/?max_rate_hz=fast", defaults).error, "");
  EXPECT_NE(parse_request_target("/?max_rate_hz=-1", defaults).error, "");
  EXPECT_NE(parse_request_target("/?colour=red", defaults).error.find("unknown query"),
            std::string::npos);
}

}  // namespace
}  // namespace avs::view
