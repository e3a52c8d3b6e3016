// The CDR reader against Cyclone's own serialiser, and its behaviour on bad input.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "avs/introspection/cdr_reader.hpp"
#include "cyclone_serializer.hpp"

namespace avs::introspection {
namespace {

using test::serializer;
using test::text;
using test::view;

std_msgs_msg_dds__Header_ make_header(std::int32_t sec, std::uint32_t nanosec,
                                      const char* frame_id) {
  std_msgs_msg_dds__Header_ header{};
  header.stamp.sec = sec;
  header.stamp.nanosec = nanosec;
  header.frame_id = text(frame_id);
  return header;
}

void expect_header(const Value& header, std::int64_t sec, std::uint64_t nanosec,
                   const std::string& frame_id) {
  EXPECT_EQ(header.at("stamp").at("sec").int_value, sec);
  EXPECT_EQ(header.at("stamp").at("nanosec").uint_value, nanosec);
  EXPECT_EQ(header.at("frame_id").string_value, frame_id);
}

std::vector<std::uint8_t> pattern_bytes(std::size_t size) {
  std::vector<std::uint8_t> bytes(size);
  for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 % 251);
  return bytes;
}

TEST(CdrReader, ImageMatchesCycloneSerialiser) {
  auto pixels = pattern_bytes(64 * 48);
  sensor_msgs_msg_dds__Image_ image{};
  image.header = make_header(1'700'000'000, 123'456'789, "camera");
  image.height = 48;
  image.width = 64;
  image.encoding = text("mono8");
  image.is_bigendian = 0;
  image.step = 64;
  image.data = view<dds_sequence_uint8>(pixels);
  const auto bytes = serializer().serialize(image);
  ASSERT_EQ(bytes[1], 0x01) << "expected CDR_LE from Cyclone on this machine";

  const auto value = decode_cdr(built_in_types(), "sensor_msgs::msg::dds_::Image_", bytes);
  EXPECT_EQ(value.type_name, "sensor_msgs::msg::dds_::Image_");
  expect_header(value.at("header"), 1'700'000'000, 123'456'789, "camera");
  EXPECT_EQ(value.at("height").uint_value, 48u);
  EXPECT_EQ(value.at("width").uint_value, 64u);
  EXPECT_EQ(value.at("encoding").string_value, "mono8");
  EXPECT_EQ(value.at("step").uint_value, 64u);
  EXPECT_EQ(value.at("data").kind, Value::Kind::kBytes);
  EXPECT_EQ(value.at("data").bytes, pixels);
}

TEST(CdrReader, JointStateMatchesCycloneSerialiser) {
  std::vector<char*> names = {text("pan"), text("tilt"), text("roll")};
  std::vector<double> position = {0.5, -1.25, 3e-9};
  std::vector<double> velocity;
  std::vector<double> effort = {1.0, 2.0, -3.5};
  sensor_msgs_msg_dds__JointState_ state{};
  state.header = make_header(-2, 999'999'999, "base");
  state.name = view<dds_sequence_string>(names);
  state.position = view<dds_sequence_double>(position);
  state.velocity = view<dds_sequence_double>(velocity);
  state.effort = view<dds_sequence_double>(effort);

  const auto value = decode_cdr(built_in_types(), "sensor_msgs::msg::dds_::JointState_",
                                serializer().serialize(state));
  expect_header(value.at("header"), -2, 999'999'999, "base");
  ASSERT_EQ(value.at("name").items.size(), 3u);
  EXPECT_EQ(value.at("name").at(2).string_value, "roll");
  ASSERT_EQ(value.at("position").items.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(value.at("position").at(i).float_value, position[i]);
    EXPECT_EQ(value.at("effort").at(i).as_double(), effort[i]);
  }
  EXPECT_TRUE(value.at("velocity").items.empty());
}

TEST(CdrReader, DiagnosticArrayMatchesCycloneSerialiser) {
  std::vector<diagnostic_msgs_msg_dds__KeyValue_> first_values = {{text("rate_hz"), text("1000")},
                                                                  {text("lost"), text("")}};
  std::vector<diagnostic_msgs_msg_dds__KeyValue_> second_values;
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> status(2);
  status[0].level = 1;
  status[0].name = text("camera");
  status[0].message = text("slow");
  status[0].hardware_id = text("cam0");
  status[0].values = view<dds_sequence_diagnostic_msgs_msg_dds__KeyValue_>(first_values);
  status[1].level = 3;
  status[1].name = text("drive");
  status[1].message = text("");
  status[1].hardware_id = text("x");
  status[1].values = view<dds_sequence_diagnostic_msgs_msg_dds__KeyValue_>(second_values);
  diagnostic_msgs_msg_dds__DiagnosticArray_ array{};
  array.header = make_header(7, 8, "");
  array.status = view<dds_sequence_diagnostic_msgs_msg_dds__DiagnosticStatus_>(status);

  const auto value = decode_cdr(built_in_types(), "diagnostic_msgs::msg::dds_::DiagnosticArray_",
                                serializer().serialize(array));
  expect_header(value.at("header"), 7, 8, "");
  const auto& decoded = value.at("status");
  ASSERT_EQ(decoded.items.size(), 2u);
  EXPECT_EQ(decoded.at(0).at("level").uint_value, 1u);
  EXPECT_EQ(decoded.at(0).at("level").primitive, Primitive::kOctet);
  EXPECT_EQ(decoded.at(0).at("hardware_id").string_value, "cam0");
  EXPECT_EQ(decoded.at(0).at("values").at(0).at("value").string_value, "1000");
  EXPECT_EQ(decoded.at(0).at("values").at(1).at("key").string_value, "lost");
  EXPECT_EQ(decoded.at(1).at("level").uint_value, 3u);
  EXPECT_EQ(decoded.at(1).at("name").string_value, "drive");
  EXPECT_TRUE(decoded.at(1).at("values").items.empty());
}

// A 12-byte image leaves cycle at body offset 88, so pan_rad needs 4 bytes of padding.
std::vector<std::uint8_t> serialized_pattern_frame() {
  auto pixels = pattern_bytes(4 * 3);
  avs_msgs_msg_dds__PatternFrame_ frame{};
  frame.header = make_header(11, 22, "cam");
  frame.image.header = make_header(33, 44, "camera_optical");
  frame.image.height = 3;
  frame.image.width = 4;
  frame.image.encoding = text("mono8");
  frame.image.step = 4;
  frame.image.data = view<dds_sequence_uint8>(pixels);
  frame.bit_index = 3;
  frame.bit_count = 9;
  frame.positive = true;
  frame.cycle = 77;
  frame.pan_rad = 0.25;
  frame.tilt_rad = -0.5;
  return serializer().serialize(frame);
}

TEST(CdrReader, PatternFrameMatchesCycloneSerialiser) {
  const auto value = decode_cdr(built_in_types(), "avs_msgs::msg::dds_::PatternFrame_",
                                serialized_pattern_frame());
  expect_header(value.at("header"), 11, 22, "cam");
  expect_header(value.at("image").at("header"), 33, 44, "camera_optical");
  EXPECT_EQ(value.at("image").at("data").bytes, pattern_bytes(12));
  EXPECT_EQ(value.at("bit_index").uint_value, 3u);
  EXPECT_EQ(value.at("bit_count").uint_value, 9u);
  EXPECT_TRUE(value.at("positive").bool_value);
  EXPECT_EQ(value.at("cycle").uint_value, 77u);
  EXPECT_EQ(value.at("pan_rad").float_value, 0.25);
  EXPECT_EQ(value.at("tilt_rad").float_value, -0.5);
}

TEST(CdrReader, PointCloud2MatchesCycloneSerialiser) {
  std::vector<sensor_msgs_msg_dds__PointField_> fields = {
      {text("x"), 0, 7, 1}, {text("y"), 4, 7, 1}, {text("intensity"), 8, 2, 1}};
  auto points = pattern_bytes(2 * 9);
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  cloud.header = make_header(1, 2, "map");
  cloud.height = 1;
  cloud.width = 2;
  cloud.fields = view<dds_sequence_sensor_msgs_msg_dds__PointField_>(fields);
  cloud.is_bigendian = false;
  cloud.point_step = 9;
  cloud.row_step = 18;
  cloud.data = view<dds_sequence_uint8>(points);
  cloud.is_dense = true;
  const auto value = decode_cdr(built_in_types(), "sensor_msgs::msg::dds_::PointCloud2_",
                                serializer().serialize(cloud));
  ASSERT_EQ(value.at("fields").items.size(), 3u);
  EXPECT_EQ(value.at("fields").at(2).at("name").string_value, "intensity");
  EXPECT_EQ(value.at("fields").at(2).at("offset").uint_value, 8u);
  EXPECT_EQ(value.at("fields").at(1).at("datatype").uint_value, 7u);
  EXPECT_EQ(value.at("row_step").uint_value, 18u);
  EXPECT_EQ(value.at("data").bytes, points);
  EXPECT_TRUE(value.at("is_dense").bool_value);
  EXPECT_FALSE(value.at("is_bigendian").bool_value);
}

TEST(CdrReader, BigEndianHeader) {
  // CDR_BE, Header{stamp{sec=-3, nanosec=258}, frame_id="ab"}.
  const std::vector<std::uint8_t> bytes = {0x00, 0x00, 0x00, 0x00,  //
                                           0xff, 0xff, 0xff, 0xfd, 0x00, 0x00, 0x01, 0x02,
                                           0x00, 0x00, 0x00, 0x03, 'a',  'b',  0x00};
  expect_header(decode_cdr(built_in_types(), "std_msgs::msg::dds_::Header_", bytes), -3, 258, "ab");
}

TEST(CdrReader, EveryTruncationIsAnErrorNamingItsOffset) {
  const auto bytes = serialized_pattern_frame();
  const std::size_t trailing_padding = bytes[3] & 0x3;  // Cyclone pads to 4, options say how much
  for (std::size_t size = 0; size + trailing_padding < bytes.size(); ++size) {
    const std::vector<std::uint8_t> prefix(bytes.begin(),
                                           bytes.begin() + static_cast<std::ptrdiff_t>(size));
    try {
      decode_cdr(built_in_types(), "avs_msgs::msg::dds_::PatternFrame_", prefix);
      ADD_FAILURE() << "a prefix of " << size << " of " << bytes.size() << " bytes decoded";
    } catch (const CdrError& error) {
      EXPECT_LE(error.offset(), size);
      if (size >= 4) {
        EXPECT_NE(std::string(error.what()).find("at byte " + std::to_string(error.offset())),
                  std::string::npos)
            << error.what();
      }
    }
  }
}

TEST(CdrReader, TruncatedImageDataNamesFieldAndOffset) {
  std::vector<std::uint8_t> bytes = {0x00, 0x01, 0x00, 0x00,              //
                                     1,    0,    0,    0,    2, 0, 0, 0,  // stamp
                                     1,    0,    0,    0,    0,           // frame_id ""
                                     0,    0,    0,                       // padding
                                     1,    0,    0,    0,    4, 0, 0, 0,  // height, width
                                     1,    0,    0,    0,    0,           // encoding ""
                                     0,                                   // is_bigendian
                                     0,    0,                             // padding
                                     4,    0,    0,    0,                 // step
                                     0,    1,    0,    0,  // data: 256 bytes announced
                                     9,    9,    9};       // ... but 3 present
  try {
    decode_cdr(built_in_types(), "sensor_msgs::msg::dds_::Image_", bytes);
    FAIL() << "truncated image decoded";
  } catch (const CdrError& error) {
    EXPECT_EQ(error.offset(), 44u);
    EXPECT_STREQ(error.what(),
                 "CDR: truncated: byte sequence needs 256 bytes, 3 left at byte 44 reading "
                 "sensor_msgs::msg::dds_::Image_.data");
  }
  bytes[40] = 3;  // now 3 bytes announced: decodes
  bytes[41] = 0;
  EXPECT_EQ(
      decode_cdr(built_in_types(), "sensor_msgs::msg::dds_::Image_", bytes).at("data").bytes.size(),
      3u);
}

TEST(CdrReader, RejectsXcdr2AndShortHeaders) {
  const std::vector<std::uint8_t> xcdr2 = {0x00, 0x07, 0x00, 0x00, 1, 0, 0, 0};
  try {
    decode_cdr(built_in_types(), "std_msgs::msg::dds_::Bool_", xcdr2);
    FAIL();
  } catch (const CdrError& error) {
    EXPECT_EQ(error.offset(), 0u);
    EXPECT_NE(std::string(error.what()).find("XCDR2"), std::string::npos) << error.what();
  }
  EXPECT_THROW(
      decode_cdr(built_in_types(), "std_msgs::msg::dds_::Bool_", std::vector<std::uint8_t>{0, 1}),
      CdrError);
  EXPECT_THROW(decode_cdr(built_in_types(), "no::Such_", std::vector<std::uint8_t>{0, 1, 0, 0, 1}),
               std::out_of_range);
}

TEST(CdrReader, RejectsBooleanOtherThanZeroOrOne) {
  const std::vector<std::uint8_t> bytes = {0x00, 0x01, 0x00, 0x00, 2};
  try {
    decode_cdr(built_in_types(), "std_msgs::msg::dds_::Bool_", bytes);
    FAIL();
  } catch (const CdrError& error) {
    EXPECT_EQ(error.offset(), 4u);
  }
  EXPECT_TRUE(decode_cdr(built_in_types(), "std_msgs::msg::dds_::Bool_",
                         std::vector<std::uint8_t>{0, 1, 0, 0, 1})
                  .at("data")
                  .bool_value);
}

// Seeded corruption: every mutated buffer either decodes or gives a CdrError; nothing else
// (no crash, no bad_alloc from a corrupt length, no other exception).
TEST(CdrReader, CorruptInputGivesErrorsNeverCrashes) {
  std::mt19937 random(20240611);
  const auto original = serialized_pattern_frame();
  int errors = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    auto bytes = original;
    const int flips = 1 + static_cast<int>(random() % 4);
    for (int i = 0; i < flips; ++i) {
      const auto at = 4 + random() % (bytes.size() - 4);
      bytes[at] = static_cast<std::uint8_t>(random() % 3 == 0 ? 0xff : random());
    }
    try {
      decode_cdr(built_in_types(), "avs_msgs::msg::dds_::PatternFrame_", bytes);
    } catch (const CdrError& error) {
      ++errors;
      EXPECT_LE(error.offset(), bytes.size());
    }
  }
  EXPECT_GT(errors, 100);  // corruption of lengths and booleans must be noticed
}

}  // namespace
}  // namespace avs::introspection
