#include "avs/runtime/dds.hpp"

#include <gtest/gtest.h>

#include "avs/msg/type_registry.hpp"
#include "avs/runtime/qos.hpp"
#include "avs/testing/test_domain.hpp"

namespace avs::runtime {
namespace {

TEST(CheckDdsTest, NegativeCodeBecomesErrorWithContext) {
  try {
    check_dds(DDS_RETCODE_BAD_PARAMETER, "create writer on rt/depth");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("create writer on rt/depth: "), std::string::npos) << e.what();
  }
  EXPECT_EQ(check_dds(3, "ok"), 3);
}

TEST(QosProfileTest, NamedProfilesFollowRos2) {
  const auto sensor = QosProfile::named("sensor_data");
  ASSERT_TRUE(sensor);
  EXPECT_EQ(sensor->reliability, Reliability::best_effort);
  EXPECT_EQ(sensor->depth, 5u);
  EXPECT_EQ(QosProfile::named("default")->reliability, Reliability::reliable);
  EXPECT_FALSE(QosProfile::named("fastest"));
}

TEST(TypeRegistryTest, KnowsRos2AndAvsTypesByDdsName) {
  for (const char* name : {"sensor_msgs::msg::dds_::Image_", "std_msgs::msg::dds_::Header_",
                           "geometry_msgs::msg::dds_::PoseStamped_", "rosgraph_msgs::msg::dds_::Clock_",
                           "diagnostic_msgs::msg::dds_::DiagnosticArray_",
                           "avs_msgs::msg::dds_::PatternFrame_"}) {
    const auto* entry = msg::find_type(name);
    ASSERT_NE(entry, nullptr) << name;
    EXPECT_STREQ(entry->descriptor->m_typename, name);
  }
}

TEST(DdsEntityTest, InvalidTopicNameIsReportedWithTheName) {
  dds::Participant participant(avs::testing::test_domain());
  const auto* type = msg::find_type("std_msgs::msg::dds_::String_");
  try {
    dds::Topic topic(participant, type->descriptor, "bad name with spaces?*", QosProfile{});
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad name with spaces"), std::string::npos) << e.what();
  }
}

TEST(DdsEntityTest, WriterSeesNoMatchedReaderInItsOwnParticipant) {
  // Same-participant samples are delivered by the container, never through DDS.
  dds::Participant participant(avs::testing::test_domain());
  const auto* type = msg::find_type("std_msgs::msg::dds_::String_");
  dds::Topic topic(participant, type->descriptor, "rt/avs_test_ignorelocal", QosProfile{});
  dds::Writer writer(participant, topic, QosProfile{});
  dds::Reader reader(participant, topic, QosProfile{});
  EXPECT_EQ(writer.matched_readers(), 0u);
}

}  // namespace
}  // namespace avs::runtime
