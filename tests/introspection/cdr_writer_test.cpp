// The CDR writer (`avs topic pub`) against Cyclone's own serialiser: the same C sample written by
// Cyclone and the same fields given as YAML give the same bytes; and what bad YAML says.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "avs/introspection/cdr_reader.hpp"
#include "avs/introspection/cdr_writer.hpp"
#include "cyclone_serializer.hpp"

namespace avs::introspection {
namespace {

using test::serializer;
using test::text;
using test::view;

std::vector<std::uint8_t> encode(std::string_view dds_name, const std::string& yaml) {
  return encode_cdr(built_in_types(), dds_name, YAML::Load(yaml));
}

/// Ours equals Cyclone's up to the padding Cyclone adds at the end (counted in the header's
/// options byte).
void expect_same_bytes(const std::vector<std::uint8_t>& ours,
                       const std::vector<std::uint8_t>& cyclone) {
  ASSERT_GE(cyclone.size(), ours.size());
  ASSERT_LT(cyclone.size(), ours.size() + 4);
  EXPECT_EQ(std::vector<std::uint8_t>(ours.begin(), ours.begin() + 3),
            std::vector<std::uint8_t>(cyclone.begin(), cyclone.begin() + 3));
  EXPECT_EQ(std::vector<std::uint8_t>(ours.begin() + 4, ours.end()),
            std::vector<std::uint8_t>(cyclone.begin() + 4,
                                      cyclone.begin() + static_cast<std::ptrdiff_t>(ours.size())));
}

TEST(CdrWriter, BoolAsCycloneWritesIt) {
  std_msgs_msg_dds__Bool_ sample{};
  sample.data = true;
  expect_same_bytes(encode("std_msgs::msg::dds_::Bool_", "{data: true}"),
                    serializer().serialize(sample));
}

TEST(CdrWriter, NestedStructsStringsAndSequences) {
  std::vector<char*> names = {text("pan"), text("tilt")};
  std::vector<double> position = {0.25, -1.5};
  sensor_msgs_msg_dds__JointState_ sample{};
  sample.header.stamp.sec = 12;
  sample.header.stamp.nanosec = 345;
  sample.header.frame_id = text("world");
  sample.name = view<dds_sequence_string>(names);
  sample.position = view<dds_sequence_double>(position);
  expect_same_bytes(
      encode("sensor_msgs::msg::dds_::JointState_",
             "{header: {stamp: {sec: 12, nanosec: 345}, frame_id: world}, name: [pan, tilt], "
             "position: [0.25, -1.5]}"),
      serializer().serialize(sample));
}

TEST(CdrWriter, ParameterEventWithUnsetFieldsZero) {
  rcl_interfaces_msg_dds__Parameter_ changed{};
  changed.name = text("threshold_psi");
  changed.value.type = 2;
  changed.value.integer_value = 30;
  changed.value.string_value = text("");
  std::vector<rcl_interfaces_msg_dds__Parameter_> list = {changed};
  rcl_interfaces_msg_dds__ParameterEvent_ sample{};
  sample.node = text("/decode");
  sample.changed_parameters = view<dds_sequence_rcl_interfaces_msg_dds__Parameter_>(list);
  expect_same_bytes(
      encode("rcl_interfaces::msg::dds_::ParameterEvent_",
             "{node: /decode, changed_parameters: [{name: threshold_psi, value: {type: 2, "
             "integer_value: 30}}]}"),
      serializer().serialize(sample));
}

TEST(CdrWriter, RoundTripsThroughTheReader) {
  const auto bytes = encode("diagnostic_msgs::msg::dds_::DiagnosticArray_",
                            "{status: [{level: 1, name: a/b, values: [{key: k, value: '3'}]}]}");
  const Value v =
      decode_cdr(built_in_types(), "diagnostic_msgs::msg::dds_::DiagnosticArray_", bytes);
  EXPECT_EQ(v.at("status").at(0).at("level").uint_value, 1u);
  EXPECT_EQ(v.at("status").at(0).at("name").string_value, "a/b");
  EXPECT_EQ(v.at("status").at(0).at("values").at(0).at("value").string_value, "3");
}

TEST(CdrWriter, BadYamlNamesTheFieldAndWhatWasExpected) {
  const auto error = [](const std::string& type, const std::string& yaml) {
    try {
      encode(type, yaml);
    } catch (const EncodeError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("std_msgs::msg::dds_::Bool_", "{data: maybe}"),
            "data: expected true or false, got 'maybe'");
  EXPECT_EQ(error("std_msgs::msg::dds_::Bool_", "{datta: true}"),
            "'datta' is not a field of std_msgs/msg/Bool (fields: data)");
  EXPECT_EQ(error("std_msgs::msg::dds_::Header_", "{stamp: {sec: 1.5}}"),
            "stamp.sec: expected an integer in [-2147483648, 2147483647], got '1.5'");
  EXPECT_EQ(error("rmw_dds_common::msg::dds_::Gid_", "{data: [1, 2]}"),
            "data: expected a list of 16, got 2");
  EXPECT_EQ(error("std_msgs::msg::dds_::Bool_", "[true]"),
            "expected a mapping of the fields of std_msgs/msg/Bool, got a list");
}

}  // namespace
}  // namespace avs::introspection
