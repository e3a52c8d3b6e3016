// sensor_msgs/CameraInfo <-> geometry::CameraModel (ROS conventions), and the camera model's
// rational distortion and coefficient handling.
#include "avs/msg/camera_info.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "avs/runtime/sample.hpp"

namespace avs::msg {
namespace {

geometry::CameraModel lens() {
  geometry::CameraModel c{
      .width = 640, .height = 480, .fx_px = 610.5, .fy_px = 612.25, .cx_px = 321.7, .cy_px = 238.9};
  c.k1 = -0.11;
  c.k2 = 0.03;
  c.p1 = 0.001;
  c.p2 = -0.0004;
  c.k3 = 0.002;
  return c;
}

TEST(CameraInfo, FollowsRosConventionsAndRoundTrips) {
  auto info = runtime::make_sample<msgs::sensor_msgs::CameraInfo>();
  to_camera_info(lens(), *info);
  EXPECT_EQ(info->width, 640u);
  EXPECT_EQ(info->height, 480u);
  EXPECT_EQ(runtime::get_string(info->distortion_model), "plumb_bob");
  ASSERT_EQ(info->d._length, 5u);
  EXPECT_EQ(info->d._buffer[0], -0.11);
  EXPECT_EQ(info->d._buffer[4], 0.002);
  const double k[9] = {610.5, 0, 321.7, 0, 612.25, 238.9, 0, 0, 1};
  const double p[12] = {610.5, 0, 321.7, 0, 0, 612.25, 238.9, 0, 0, 0, 1, 0};
  for (int i = 0; i < 9; ++i) EXPECT_EQ(info->k[i], k[i]) << "K[" << i << "]";
  for (int i = 0; i < 9; ++i) EXPECT_EQ(info->r[i], i % 4 == 0 ? 1.0 : 0.0) << "R[" << i << "]";
  for (int i = 0; i < 12; ++i) EXPECT_EQ(info->p[i], p[i]) << "P[" << i << "]";
  std::string why;
  const auto back = from_camera_info(*info, &why);
  ASSERT_TRUE(back.has_value()) << why;
  EXPECT_EQ(*back, lens());
}

TEST(CameraInfo, RationalPolynomialCarriesEightCoefficients) {
  geometry::CameraModel c = lens();
  c.k4 = 0.01;
  c.k6 = -0.002;
  auto info = runtime::make_sample<msgs::sensor_msgs::CameraInfo>();
  to_camera_info(c, *info);
  EXPECT_EQ(runtime::get_string(info->distortion_model), "rational_polynomial");
  ASSERT_EQ(info->d._length, 8u);
  EXPECT_EQ(info->d._buffer[7], -0.002);
  const auto back = from_camera_info(*info);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, c);
}

TEST(CameraInfo, WhatAvsCannotUseIsRefusedWithAReason) {
  auto info = runtime::make_sample<msgs::sensor_msgs::CameraInfo>();
  to_camera_info(lens(), *info);
  std::string why;
  runtime::set_string(info->distortion_model, "equidistant");
  EXPECT_FALSE(from_camera_info(*info, &why).has_value());
  EXPECT_NE(why.find("equidistant"), std::string::npos) << why;
  to_camera_info(lens(), *info);
  runtime::resize_sequence(info->d, 4);
  EXPECT_FALSE(from_camera_info(*info, &why).has_value());
  EXPECT_NE(why.find("needs 5 coefficients"), std::string::npos) << why;
  to_camera_info(lens(), *info);
  info->k[0] = 0;
  EXPECT_FALSE(from_camera_info(*info, &why).has_value());
  EXPECT_NE(why.find("focal"), std::string::npos) << why;
  to_camera_info(lens(), *info);
  info->k[0] = std::nan("");
  EXPECT_FALSE(from_camera_info(*info, &why).has_value());
  to_camera_info(lens(), *info);
  info->width = 0;
  EXPECT_FALSE(from_camera_info(*info, &why).has_value());
  EXPECT_NE(why.find("image size"), std::string::npos) << why;
  to_camera_info(lens(), *info);
  info->binning_x = 2;
  EXPECT_FALSE(from_camera_info(*info, &why).has_value());
}

TEST(CameraModel, RationalDistortionInvertsAndCoefficientCountsAreChecked) {
  geometry::CameraModel c = lens();
  c.k4 = 0.05;
  c.k5 = -0.01;
  c.k6 = 0.003;
  for (const double x : {-0.4, -0.1, 0.0, 0.25, 0.45}) {
    for (const double y : {-0.3, 0.0, 0.35}) {
      const Eigen::Vector2d ideal(x, y);
      EXPECT_LT((c.undistort(c.distort(ideal)) - ideal).norm(), 1e-10);
      const Eigen::Vector3d p(x, y, 1.0);
      const Eigen::Vector2d uv = c.project(p * 2.0);
      EXPECT_LT((c.ray(uv.x(), uv.y()) - p).norm(), 1e-9);
    }
  }
  const double five[5] = {0.1, 0.2, 0.3, 0.4, 0.5};
  geometry::CameraModel d = lens();
  EXPECT_TRUE(d.set_distortion_coefficients(five));
  EXPECT_EQ(d.k3, 0.5);
  EXPECT_EQ(d.k4, 0.0);
  const double three[3] = {0.1, 0.2, 0.3};
  EXPECT_FALSE(d.set_distortion_coefficients(three));
  EXPECT_EQ(d.k1, 0.1) << "unchanged";
  EXPECT_TRUE(d.set_distortion_coefficients({}));
  EXPECT_FALSE(d.has_distortion());
  EXPECT_TRUE(lens().problem().empty());
}

}  // namespace
}  // namespace avs::msg
