// ClientSession: subscriptions, the bounded drop-oldest queue, throttling, rejections.
#include "avs/view/client_session.hpp"

#include <gtest/gtest.h>

namespace avs::view {
namespace {

Payload bytes(std::uint8_t v) {
  return std::make_shared<const std::vector<std::uint8_t>>(std::vector<std::uint8_t>{v});
}

const auto kAllExist = [](ChannelId) { return true; };

std::vector<std::uint8_t> drain_data(ClientSession& s) {
  std::vector<std::uint8_t> out;
  while (auto m = s.next()) {
    if (!m->is_text) out.push_back((*m->payload)[0]);
  }
  return out;
}

TEST(ViewClientSession, ControlMessagesGoFirst) {
  ClientSession s({}, {});
  s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":1}]})", kAllExist);
  s.offer(1, false, 10, bytes(1));
  s.queue_text("advertise");
  auto m = s.next();
  ASSERT_TRUE(m && m->is_text);
  EXPECT_EQ(m->text, "advertise");
  m = s.next();
  ASSERT_TRUE(m && !m->is_text);
  EXPECT_EQ(m->header, message_data_header(5, 10));
  EXPECT_FALSE(s.next());
}

TEST(ViewClientSession, FullQueueDropsTheOldestAndCountsIt) {
  SessionLimits limits;
  limits.queue_depth = 3;
  ClientSession s({}, limits);
  const auto changes =
      s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":2}]})", kAllExist);
  EXPECT_EQ(changes.subscribed, (std::vector<ChannelId>{2}));
  for (std::uint8_t i = 0; i < 10; ++i) s.offer(2, false, i, bytes(i));
  s.offer(9, false, 0, bytes(99));  // not subscribed: ignored
  EXPECT_EQ(s.dropped_total(), 7u);
  EXPECT_EQ(s.counters().at(0).queued, 3u);
  EXPECT_EQ(drain_data(s), (std::vector<std::uint8_t>{7, 8, 9}));
  EXPECT_EQ(s.sent_total(), 3u);
}

TEST(ViewClientSession, MaxRateThinsImagesOnly) {
  ClientSession s(ClientOptions{10.0}, {});  // 10 Hz: at least 100 ms apart
  s.handle_text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":1,"channelId":2}]})",
      kAllExist);
  for (std::uint8_t i = 0; i < 8; ++i) {
    const std::uint64_t t = i * 40'000'000ull;  // 25 Hz
    s.offer(1, true, t, bytes(i));
    if (i < 4) s.offer(2, false, t, bytes(100 + i));
    drain_data(s);
  }
  const auto c = s.counters();
  EXPECT_EQ(c.at(0).sent, 3u);  // t = 0, 120, 240 ms
  EXPECT_EQ(c.at(0).throttled, 5u);
  EXPECT_EQ(c.at(1).sent, 4u);
  EXPECT_EQ(c.at(1).throttled, 0u);
}

TEST(ViewClientSession, RoundRobinAcrossSubscriptions) {
  ClientSession s({}, {});
  s.handle_text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":1,"channelId":2}]})",
      kAllExist);
  for (std::uint8_t i = 0; i < 3; ++i) s.offer(1, false, i, bytes(10 + i));
  for (std::uint8_t i = 0; i < 3; ++i) s.offer(2, false, i, bytes(20 + i));
  EXPECT_EQ(drain_data(s), (std::vector<std::uint8_t>{10, 20, 11, 21, 12, 22}));
}

TEST(ViewClientSession, BadRequestsAreRejectedWithAStatus) {
  ClientSession s({}, {});
  const auto exists = [](ChannelId id) { return id == 1; };
  s.handle_text("{", exists);
  s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":4}]})", exists);
  s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1}]})", exists);
  s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1}]})", exists);
  s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})", exists);
  s.handle_text(R"({"op":"unsubscribe","subscriptionIds":[3]})", exists);
  s.reject("binary");
  EXPECT_EQ(s.rejected_requests(), 6u);
  EXPECT_EQ(s.last_rejection(), "binary");
  int statuses = 0;
  while (auto m = s.next()) {
    ASSERT_TRUE(m->is_text);
    EXPECT_NE(m->text.find(R"("level":2)"), std::string::npos) << m->text;
    ++statuses;
  }
  EXPECT_EQ(statuses, 6);
  EXPECT_EQ(s.subscribed_channels(), (std::vector<ChannelId>{1}));
}

TEST(ViewClientSession, StatusFloodIsBounded) {
  SessionLimits limits;
  limits.control_queue_depth = 4;
  ClientSession s({}, limits);
  for (int i = 0; i < 100; ++i) s.handle_text("x", kAllExist);
  EXPECT_EQ(s.rejected_requests(), 100u);
  int n = 0;
  while (s.next()) ++n;
  EXPECT_EQ(n, 4);
}

TEST(ViewClientSession, UnsubscribeAndRemovedChannel) {
  ClientSession s({}, {});
  s.handle_text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":1,"channelId":2}]})",
      kAllExist);
  s.offer(1, false, 0, bytes(1));
  const auto changes = s.handle_text(R"({"op":"unsubscribe","subscriptionIds":[0]})", kAllExist);
  EXPECT_EQ(changes.unsubscribed, (std::vector<ChannelId>{1}));
  EXPECT_TRUE(drain_data(s).empty());  // its queue went with it
  EXPECT_TRUE(s.remove_channel(2));
  EXPECT_FALSE(s.remove_channel(2));
  EXPECT_TRUE(s.subscribed_channels().empty());
  // The subscription id is free again.
  s.handle_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":2}]})", kAllExist);
  EXPECT_EQ(s.rejected_requests(), 0u);
}

}  // namespace
}  // namespace avs::view
