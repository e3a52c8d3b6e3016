// YAML printing of decoded samples, in the shape `ros2 topic echo` prints.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "avs/introspection/cdr_reader.hpp"
#include "cyclone_serializer.hpp"

namespace avs::introspection {
namespace {

using test::serializer;
using test::text;
using test::view;

TEST(Yaml, JointStateLikeRos2TopicEcho) {
  std::vector<char*> names = {text("pan"), text("tilt: 2"), text("")};
  std::vector<double> position = {0.5, -1.0, 1e-05};
  std::vector<double> velocity;
  std::vector<double> effort = {1.0, 2.0, 3.0, 4.0};
  sensor_msgs_msg_dds__JointState_ state{};
  state.header.stamp.sec = 12;
  state.header.stamp.nanosec = 345;
  state.header.frame_id = text("base");
  state.name = view<dds_sequence_string>(names);
  state.position = view<dds_sequence_double>(position);
  state.velocity = view<dds_sequence_double>(velocity);
  state.effort = view<dds_sequence_double>(effort);
  const auto value = decode_cdr(built_in_types(), "sensor_msgs::msg::dds_::JointState_",
                                serializer().serialize(state));
  YamlOptions options;
  options.max_list_elements = 3;
  EXPECT_EQ(to_yaml(value, options),
            "header:\n"
            "  stamp:\n"
            "    sec: 12\n"
            "    nanosec: 345\n"
            "  frame_id: base\n"
            "name:\n"
            "- pan\n"
            "- 'tilt: 2'\n"
            "- ''\n"
            "position:\n"
            "- 0.5\n"
            "- -1.0\n"
            "- 1.0e-05\n"
            "velocity: []\n"
            "effort:\n"
            "- 1.0\n"
            "- 2.0\n"
            "- 3.0\n"
            "- ... (1 more)\n");
}

TEST(Yaml, ImageDataSummarisedAndStructListsIndented) {
  std::vector<std::uint8_t> pixels(12, 7);
  avs_msgs_msg_dds__PatternFrame_ frame{};
  frame.header.frame_id = text("0");
  frame.image.header.frame_id = text("cam\n1");
  frame.image.encoding = text("mono8");
  frame.image.height = 3;
  frame.image.width = 4;
  frame.image.step = 4;
  frame.image.data = view<dds_sequence_uint8>(pixels);
  frame.positive = true;
  frame.pan_rad = 0.1;
  const auto value = decode_cdr(built_in_types(), "avs_msgs::msg::dds_::PatternFrame_",
                                serializer().serialize(frame));
  const auto yaml = to_yaml(value);
  EXPECT_NE(yaml.find("  data: <12 bytes>\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("  frame_id: '0'\n"), std::string::npos) << yaml;  // would read as a number
  EXPECT_NE(yaml.find("    frame_id: \"cam\\n1\"\n"), std::string::npos)
      << yaml;  // control characters escaped
  EXPECT_NE(yaml.find("positive: true\ncycle: 0\npan_rad: 0.1\n"), std::string::npos) << yaml;

  YamlOptions full;
  full.summarize_image_data = false;
  EXPECT_NE(to_yaml(value, full).find("  data:\n  - 7\n  - 7\n"), std::string::npos);

  std::vector<diagnostic_msgs_msg_dds__KeyValue_> values = {{text("a"), text("b")}};
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> status(1);
  status[0].level = 2;
  status[0].name = text("n");
  status[0].message = text("m");
  status[0].hardware_id = text("h");
  status[0].values = view<dds_sequence_diagnostic_msgs_msg_dds__KeyValue_>(values);
  diagnostic_msgs_msg_dds__DiagnosticArray_ array{};
  array.header.frame_id = text("f");
  array.status = view<dds_sequence_diagnostic_msgs_msg_dds__DiagnosticStatus_>(status);
  EXPECT_EQ(to_yaml(decode_cdr(built_in_types(), "diagnostic_msgs::msg::dds_::DiagnosticArray_",
                               serializer().serialize(array))),
            "header:\n"
            "  stamp:\n"
            "    sec: 0\n"
            "    nanosec: 0\n"
            "  frame_id: f\n"
            "status:\n"
            "- level: 2\n"
            "  name: n\n"
            "  message: m\n"
            "  hardware_id: h\n"
            "  values:\n"
            "  - key: a\n"
            "    value: b\n");
}

TEST(Yaml, LongByteSequencesAndStringsShortened) {
  Value value;
  value.type_name = "test::T_";
  value.names = {"blob", "label"};
  Value blob;
  blob.kind = Value::Kind::kBytes;
  blob.bytes.assign(262144, 1);
  Value label;
  label.kind = Value::Kind::kString;
  label.string_value = std::string(200, 'x');
  value.items = {blob, label};
  EXPECT_EQ(to_yaml(value), "blob: <262144 bytes>\nlabel: " + std::string(128, 'x') + "...\n");
}

}  // namespace
}  // namespace avs::introspection
