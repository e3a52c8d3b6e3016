// libs/bag's replay timing (replay_schedule.hpp): header stamps read from CDR, the schedule's
// rules, and a serialised sample's round trip through the runtime's CdrCodec.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <vector>

#include "avs/bag/replay_schedule.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/testing/test_domain.hpp"
#include "geometry_msgs.h"

namespace avs::bag {
namespace {

std::vector<std::byte> bytes(std::initializer_list<int> list) {
  std::vector<std::byte> out;
  for (int b : list) out.push_back(static_cast<std::byte>(b));
  return out;
}

TEST(HeaderStamp, ReadsLittleAndBigEndianCdrAndRefusesWhatIsNotAStamp) {
  // sec 2, nanosec 500000000 (0x1DCD6500).
  EXPECT_EQ(header_stamp_ns(bytes({0, 1, 0, 0, 2, 0, 0, 0, 0x00, 0x65, 0xCD, 0x1D})),
            2'500'000'000);
  EXPECT_EQ(header_stamp_ns(bytes({0, 0, 0, 0, 0, 0, 0, 2, 0x1D, 0xCD, 0x65, 0x00})),
            2'500'000'000);
  EXPECT_EQ(header_stamp_ns(bytes({0, 7, 0, 0, 2, 0, 0, 0, 0x00, 0x65, 0xCD, 0x1D})),
            2'500'000'000);
  EXPECT_EQ(header_stamp_ns(bytes({0, 1, 0, 0, 2, 0, 0, 0})), std::nullopt) << "too short";
  EXPECT_EQ(header_stamp_ns(bytes({0, 3, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0})), std::nullopt)
      << "parameter-list CDR is not read";
  EXPECT_EQ(header_stamp_ns(bytes({0, 1, 0, 0, 2, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF})),
            std::nullopt)
      << "nanosec out of range";
}

TEST(HeaderStamp, TheRealSerialisationOfAStampedMessage) {
  runtime::dds::Participant participant(avs::testing::test_domain());
  const msg::TypeEntry* type = msg::find_type("geometry_msgs::msg::dds_::PoseStamped_");
  ASSERT_NE(type, nullptr);
  runtime::dds::CdrCodec codec(participant, *type);
  auto pose = runtime::make_sample<geometry_msgs_msg_dds__PoseStamped_>();
  pose->header.stamp.sec = 7;
  pose->header.stamp.nanosec = 123;
  runtime::set_string(pose->header.frame_id, "camera_optical_frame");
  pose->pose.position.x = 0.25;
  pose->pose.orientation.w = 1;
  const std::vector<std::byte> cdr = codec.to_cdr(pose.get());
  EXPECT_EQ(header_stamp_ns(cdr), 7'000'000'123);
  const auto back =
      std::static_pointer_cast<geometry_msgs_msg_dds__PoseStamped_>(codec.to_sample(cdr));
  EXPECT_EQ(back->pose.position.x, 0.25);
  EXPECT_STREQ(back->header.frame_id, "camera_optical_frame");
  std::vector<std::byte> cut(cdr.begin(), cdr.begin() + 10);
  EXPECT_THROW(codec.to_sample(cut), runtime::Error) << "truncated CDR is refused";
}

TEST(StartsWithHeader, FirstFieldAfterCommentsAndBlankLines) {
  EXPECT_TRUE(starts_with_header("# exposure\n\nstd_msgs/Header header\nfloat64 x\n"));
  EXPECT_TRUE(starts_with_header("std_msgs/msg/Header header"));
  EXPECT_FALSE(starts_with_header("builtin_interfaces/Time clock\n"));
  EXPECT_FALSE(starts_with_header("float64 x\nstd_msgs/Header header\n"));
  EXPECT_FALSE(starts_with_header(""));
}

TEST(ReplaySchedule, StampsFirstLogTimesMovedOntoThemAndNeverReordered) {
  ReplaySchedule s(ReplaySchedule::Clock::header);
  // A header-less message before any stamp: at once.
  EXPECT_EQ(s.due_ns(5'000, std::nullopt), ReplaySchedule::kAtOnce);
  EXPECT_EQ(s.due_ns(1'000'000, 10), 10);  // stamped: its stamp (log - stamp = 999990)
  EXPECT_EQ(s.due_ns(1'000'050, std::nullopt), 60) << "log time moved onto the stamps";
  EXPECT_EQ(s.due_ns(1'000'100, 40), 60) << "never before the message ahead of it";
  EXPECT_EQ(s.due_ns(1'000'200, 300), 300);

  ReplaySchedule log(ReplaySchedule::Clock::log);
  EXPECT_EQ(log.due_ns(1'000, 999'999), 1'000);
  EXPECT_EQ(log.due_ns(900, std::nullopt), 1'000);
}

}  // namespace
}  // namespace avs::bag
