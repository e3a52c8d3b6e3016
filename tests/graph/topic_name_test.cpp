#include <gtest/gtest.h>

#include "avs/runtime/error.hpp"
#include "avs/runtime/topic_name.hpp"

namespace avs::runtime {
namespace {

TEST(TopicName, ResolvesRelativeNamesAgainstNamespace) {
  EXPECT_EQ(resolve_topic_name("/", "depth"), "/depth");
  EXPECT_EQ(resolve_topic_name("/avs", "depth"), "/avs/depth");
  EXPECT_EQ(resolve_topic_name("/avs", "cam/image"), "/avs/cam/image");
  EXPECT_EQ(resolve_topic_name("/avs", "/depth"), "/depth");
}

TEST(TopicName, RejectsInvalidNames) {
  EXPECT_THROW(resolve_topic_name("/", ""), Error);
  EXPECT_THROW(resolve_topic_name("/", "a//b"), Error);
  EXPECT_THROW(resolve_topic_name("/", "a-b"), Error);
  EXPECT_THROW(resolve_topic_name("/", "a/"), Error);
  EXPECT_THROW(resolve_topic_name("/", "/"), Error);
  EXPECT_THROW(resolve_topic_name("/", "cam/2d"), Error);  // token starting with a digit
  EXPECT_THROW(resolve_topic_name("avs", "x"), Error);     // namespace must be absolute
  EXPECT_THROW(resolve_topic_name("/", "/" + std::string(300, 'a')), Error);
}

TEST(TopicName, DdsPrefixRoundTrip) {
  EXPECT_EQ(to_dds_topic_name("/depth"), "rt/depth");
  EXPECT_EQ(to_dds_topic_name("/robot1/cam/image_raw"), "rt/robot1/cam/image_raw");
  EXPECT_EQ(from_dds_topic_name("rt/depth"), "/depth");
  EXPECT_EQ(from_dds_topic_name("rtx/depth"), "rtx/depth");
  EXPECT_EQ(from_dds_topic_name("DCPSPublication"), "DCPSPublication");
  EXPECT_THROW(to_dds_topic_name("depth"), Error);
}

TEST(TopicName, RosTypeNames) {
  EXPECT_EQ(to_ros_type_name("sensor_msgs::msg::dds_::Image_"), "sensor_msgs/msg/Image");
  EXPECT_EQ(to_ros_type_name("avs::msg::dds_::PatternFrame_"), "avs/msg/PatternFrame");
  EXPECT_EQ(to_ros_type_name("Plain"), "Plain");
  EXPECT_EQ(to_ros_type_name("pkg::msg::dds_::NoUnderscore"), "pkg::msg::dds_::NoUnderscore");
}

}  // namespace
}  // namespace avs::runtime
