// ros2msg schema text, compared with the ROS 2 .msg definitions (reference doc 4b) laid out
// as rosbag2's get_full_text does (reference doc 4c).
#include <gtest/gtest.h>

#include <string>

#include "avs/introspection/type_database.hpp"

namespace avs::introspection {
namespace {

const std::string kDelimiter = "\n" + std::string(80, '=') + "\n";

const std::string kTimeMsg = "int32 sec\nuint32 nanosec\n";
const std::string kHeaderMsg = "builtin_interfaces/Time stamp\nstring frame_id\n";

TEST(RosTypeName, DemanglesLikeRmwCyclonedds) {
  EXPECT_EQ(ros_type_name("sensor_msgs::msg::dds_::Image_"), "sensor_msgs/msg/Image");
  EXPECT_EQ(ros_type_name("avs_msgs::msg::dds_::PatternFrame_"), "avs_msgs/msg/PatternFrame");
  EXPECT_EQ(ros_type_name("plain::Type"), "plain::Type");  // no dds_:: -> unchanged
  EXPECT_EQ(ros_type_name("a::msg::dds_::NoUnderscore"), "a::msg::dds_::NoUnderscore");
}

TEST(RosTypeName, MangleIsTheInverse) {
  for (const auto& [name, type] : built_in_types().types()) {
    EXPECT_EQ(dds_type_name(ros_type_name(name)), name);
  }
  EXPECT_EQ(dds_type_name("std_msgs/msg/Header"), "std_msgs::msg::dds_::Header_");
  EXPECT_EQ(dds_type_name("std_msgs/Header"), "std_msgs::msg::dds_::Header_");  // ros2's short form
  EXPECT_EQ(dds_type_name("std_msgs/"), "");
  EXPECT_EQ(dds_type_name("/Header"), "");
  EXPECT_EQ(dds_type_name("a/b/c/d"), "");
  EXPECT_EQ(dds_type_name("/msg/X"), "");
}

TEST(Ros2Msg, Header) {
  EXPECT_EQ(ros2msg_definition(built_in_types(), "std_msgs::msg::dds_::Header_"),
            kHeaderMsg + kDelimiter + "MSG: builtin_interfaces/Time\n" + kTimeMsg);
}

TEST(Ros2Msg, Image) {
  const std::string expected =
      "std_msgs/Header header\n"
      "uint32 height\n"
      "uint32 width\n"
      "string encoding\n"
      "uint8 is_bigendian\n"
      "uint32 step\n"
      "uint8[] data\n" +
      kDelimiter + "MSG: std_msgs/Header\n" + kHeaderMsg +  //
      kDelimiter + "MSG: builtin_interfaces/Time\n" + kTimeMsg;
  EXPECT_EQ(ros2msg_definition(built_in_types(), "sensor_msgs::msg::dds_::Image_"), expected);
}

TEST(Ros2Msg, PointCloud2SamePackageUnqualifiedWithConstants) {
  const std::string expected =
      "std_msgs/Header header\n"
      "uint32 height\n"
      "uint32 width\n"
      "PointField[] fields\n"
      "bool is_bigendian\n"
      "uint32 point_step\n"
      "uint32 row_step\n"
      "uint8[] data\n"
      "bool is_dense\n" +
      // "sensor_msgs/PointField" sorts before "std_msgs/Header".
      kDelimiter + "MSG: sensor_msgs/PointField\n" +
      "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\n"
      "uint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\n"
      "string name\nuint32 offset\nuint8 datatype\nuint32 count\n" +
      kDelimiter + "MSG: std_msgs/Header\n" + kHeaderMsg +  //
      kDelimiter + "MSG: builtin_interfaces/Time\n" + kTimeMsg;
  EXPECT_EQ(ros2msg_definition(built_in_types(), "sensor_msgs::msg::dds_::PointCloud2_"), expected);
}

TEST(Ros2Msg, DependenciesDepthFirstEachOnce) {
  // GroundTruth uses Pose twice and Header once: Pose (then its Point, Quaternion) before
  // Header (then Time), each exactly once.
  const std::string expected =
      "std_msgs/Header header\n"
      "string object_name\n"
      "geometry_msgs/Pose pose_world\n"
      "geometry_msgs/Pose pose_camera\n"
      "float64 pan_rad\nfloat64 tilt_rad\nfloat64 pan_velocity_rad_s\nfloat64 "
      "tilt_velocity_rad_s\n" +
      kDelimiter + "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n" +
      kDelimiter + "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n" + kDelimiter +
      "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n" + kDelimiter +
      "MSG: std_msgs/Header\n" + kHeaderMsg +  //
      kDelimiter + "MSG: builtin_interfaces/Time\n" + kTimeMsg;
  EXPECT_EQ(ros2msg_definition(built_in_types(), "avs_msgs::msg::dds_::GroundTruth_"), expected);
}

TEST(Ros2Msg, DiagnosticStatusByteConstants) {
  const auto text =
      ros2msg_definition(built_in_types(), "diagnostic_msgs::msg::dds_::DiagnosticArray_");
  EXPECT_EQ(text.substr(0, text.find('\n', text.find("status")) + 1),
            "std_msgs/Header header\nDiagnosticStatus[] status\n");
  EXPECT_NE(
      text.find("MSG: diagnostic_msgs/DiagnosticStatus\nbyte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte "
                "STALE=3\n"
                "byte level\nstring name\nstring message\nstring hardware_id\nKeyValue[] values\n"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("MSG: diagnostic_msgs/KeyValue\nstring key\nstring value\n"),
            std::string::npos);
}

TEST(Ros2Msg, ArraysAndBounds) {
  TypeDatabase database;
  database.add_idl("t.idl", R"(module p { module msg { module dds_ {
    module T_Constants { const string NAME = "x"; const double GAIN = -2.5; };
    struct T_ { double v[3]; sequence<int32, 5> s; string<10> label; sequence<string<4>> tags; };
  }; }; };)");
  database.resolve();
  EXPECT_EQ(ros2msg_definition(database, "p::msg::dds_::T_"),
            "string NAME=\"x\"\nfloat64 GAIN=-2.5\nfloat64[3] v\nint32[<=5] s\nstring<=10 "
            "label\nstring<=4[] tags\n");
  EXPECT_THROW(ros2msg_definition(database, "p::msg::dds_::Unknown_"), std::out_of_range);
}

}  // namespace
}  // namespace avs::introspection
