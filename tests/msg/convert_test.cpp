// The message layer's conversions (avs/msg/convert.hpp): poses, xyz clouds, joints by name,
// name lists; bad samples give a reason, never an exception or an out-of-bounds read.
#include "avs/msg/convert.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "avs/runtime/sample.hpp"

namespace avs::msg {
namespace {

TEST(Convert, PoseRoundTripsAndNonFinitePosesAreSeen) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.1, -0.2, 1.3);
  msgs::geometry_msgs::Pose pose{};
  to_pose(T, pose);
  EXPECT_TRUE(is_finite(pose));
  EXPECT_TRUE(to_isometry(pose).isApprox(T, 1e-12));
  pose.orientation.x *= 2;  // not unit: normalised on the way back
  EXPECT_TRUE(to_isometry(pose).linear().isUnitary(1e-12));
  pose.position.y = std::nan("");
  EXPECT_FALSE(is_finite(pose));
  msgs::geometry_msgs::Pose zero{};
  EXPECT_FALSE(is_finite(zero)) << "a zero quaternion is no rotation";
}

TEST(Convert, XyzCloudRoundTripsAndBadLayoutsAreRefused) {
  const std::vector<Eigen::Vector3f> points = {{0.1F, 0.2F, 1.0F}, {-0.3F, 0.0F, 2.0F}};
  auto cloud = runtime::make_sample<msgs::sensor_msgs::PointCloud2>();
  write_xyz_cloud(points, *cloud);
  EXPECT_EQ(cloud->width, 2u);
  EXPECT_EQ(cloud->point_step, 12u);
  std::string why;
  auto back = read_xyz_cloud(*cloud, &why);
  ASSERT_TRUE(back.has_value()) << why;
  ASSERT_EQ(back->size(), 2u);
  EXPECT_NEAR((*back)[1].z(), 2.0, 1e-7);

  cloud->fields._buffer[2].offset = 1u << 30;  // z far outside the point
  EXPECT_FALSE(read_xyz_cloud(*cloud, &why).has_value());
  EXPECT_NE(why.find("outside point_step"), std::string::npos) << why;
  write_xyz_cloud(points, *cloud);
  cloud->width = 1000;  // more points than data
  EXPECT_FALSE(read_xyz_cloud(*cloud, &why).has_value());
  EXPECT_NE(why.find("bytes of data"), std::string::npos) << why;
  write_xyz_cloud(points, *cloud);
  cloud->fields._buffer[0].datatype = sensor_msgs_msg_dds__PointField_Constants_FLOAT64;
  EXPECT_FALSE(read_xyz_cloud(*cloud, &why).has_value());
}

TEST(Convert, JointsAreFoundByNameAndNameListsAreChecked) {
  auto state = runtime::make_sample<msgs::sensor_msgs::JointState>();
  runtime::resize_sequence(state->name, 2);
  runtime::set_string(state->name._buffer[0], "tilt");
  runtime::set_string(state->name._buffer[1], "pan");
  runtime::resize_sequence(state->position, 2);
  state->position._buffer[0] = 0.2;
  state->position._buffer[1] = -0.4;
  runtime::resize_sequence(state->velocity, 1);
  state->velocity._buffer[0] = 3.0;
  const auto pan = find_joint(*state, "pan");
  ASSERT_TRUE(pan.has_value());
  EXPECT_EQ(pan->position, -0.4);
  EXPECT_EQ(pan->velocity, 0.0) << "no velocity for it";
  EXPECT_EQ(find_joint(*state, "tilt")->velocity, 3.0);
  EXPECT_FALSE(find_joint(*state, "roll").has_value());

  EXPECT_EQ(parse_name_list("pan,tilt", 2, "joint_names"),
            (std::vector<std::string>{"pan", "tilt"}));
  EXPECT_THROW(parse_name_list("pan", 2, "joint_names"), std::invalid_argument);
  EXPECT_THROW(parse_name_list("pan,", 2, "joint_names"), std::invalid_argument);
  EXPECT_THROW(parse_name_list("a,b,c", 2, "joint_names"), std::invalid_argument);
  EXPECT_EQ(parse_name_list(" pan ,\ttilt", 2, "joint_names"),
            (std::vector<std::string>{"pan", "tilt"}));
  EXPECT_EQ(parse_name_list("a,b,c", 0, "axis_names"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_THROW(parse_name_list("", 0, "axis_names"), std::invalid_argument);
  EXPECT_THROW(parse_name_list("a, ,c", 0, "axis_names"), std::invalid_argument);
}

}  // namespace
}  // namespace avs::msg
