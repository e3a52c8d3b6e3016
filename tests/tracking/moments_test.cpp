#include "avs/tracking/moments.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "depth_image.hpp"

namespace avs::tracking {
namespace {

constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();

using test::Image;
const geometry::CameraModel& camera = test::kCamera;

TEST(Moments, RectangleGivesAreaCentroidAndMeanDepth) {
  Image img;
  img.fill_rect(40, 10, 10, 6, 1.0f);  // u 40..49, v 10..15
  img.fill_rect(40, 10, 5, 6, 1.2f);   // left half nearer the far edge of the window
  const TargetObservation obs = measure_target(img.view(), camera, {0.5, 1.5, 10});
  EXPECT_TRUE(obs.present);
  EXPECT_DOUBLE_EQ(obs.m00, 60);
  EXPECT_DOUBLE_EQ(obs.centroid_u_px, 44.5);
  EXPECT_DOUBLE_EQ(obs.centroid_v_px, 12.5);
  EXPECT_NEAR(obs.m_g_px.x(), 44.5 - 31.5, 1e-12);
  EXPECT_NEAR(obs.m_g_px.y(), 12.5 - 23.5, 1e-12);
  EXPECT_NEAR(obs.m10, 60 * 13.0, 1e-9);  // Eq. 7 about the principal point
  EXPECT_NEAR(obs.m01, 60 * -11.0, 1e-9);
  EXPECT_NEAR(obs.mean_depth_m, 1.1, 1e-6);
}

TEST(Moments, DepthWindowIsStrictAndNanIsNotTarget) {
  Image img;
  img.fill_rect(0, 0, 4, 4, 0.5f);   // == phi_l: excluded (Eq. 8 is strict)
  img.fill_rect(10, 0, 4, 4, 1.5f);  // == phi_h: excluded
  img.fill_rect(20, 0, 4, 4, nan_f);
  img.fill_rect(30, 0, 3, 3, 0.9f);  // the only target: 9 px
  const TargetObservation obs = measure_target(img.view(), camera, {0.5, 1.5, 5});
  EXPECT_DOUBLE_EQ(obs.m00, 9);
  EXPECT_DOUBLE_EQ(obs.centroid_u_px, 31);
}

TEST(Moments, MinimumAreaDecidesPresence) {
  Image img;
  img.fill_rect(30, 20, 3, 3, 1.0f);
  EXPECT_FALSE(measure_target(img.view(), camera, {0.5, 1.5, 10}).present);
  EXPECT_TRUE(measure_target(img.view(), camera, {0.5, 1.5, 9}).present);
  Image empty;
  const TargetObservation none = measure_target(empty.view(), camera, {0.5, 1.5, 0});
  EXPECT_FALSE(none.present);
  EXPECT_EQ(none.m00, 0);
}

TEST(Moments, RowStrideIsHonoured) {
  Image img;
  img.fill_rect(40, 5, 2, 2, 1.0f);  // right half: outside a 32-wide view with stride 64
  img.fill_rect(3, 7, 1, 1, 1.0f);   // left half: inside
  const geometry::DepthView left_half{img.depth.data(), 32, 48, 64};
  const TargetObservation obs = measure_target(left_half, camera, {0.5, 1.5, 1});
  EXPECT_DOUBLE_EQ(obs.m00, 1);
  EXPECT_DOUBLE_EQ(obs.centroid_u_px, 3);
  EXPECT_DOUBLE_EQ(obs.centroid_v_px, 7);
}

TEST(Moments, WithLensDistortionTheCentroidIsUndistortedForTheServoLaw) {
  // A target off centre under barrel distortion: the image centroid sits nearer the centre
  // than the ideal pinhole's; m_g (what Eq. 10 relates to the direction) is the undistorted one.
  geometry::CameraModel lens = camera;
  lens.k1 = -0.2;
  lens.k2 = 0.05;
  Image img;
  img.fill_rect(50, 30, 6, 6, 1.0f);  // u 50..55, v 30..35: centroid (52.5, 32.5)
  const TargetObservation obs = measure_target(img.view(), lens, {0.5, 1.5, 10});
  ASSERT_TRUE(obs.present);
  EXPECT_DOUBLE_EQ(obs.centroid_u_px, 52.5);
  EXPECT_DOUBLE_EQ(obs.centroid_v_px, 32.5);
  const Eigen::Vector3d ray = lens.ray(52.5, 32.5);
  EXPECT_NEAR(obs.m_g_px.x(), 100.0 * ray.x(), 1e-9);
  EXPECT_NEAR(obs.m_g_px.y(), 100.0 * ray.y(), 1e-9);
  EXPECT_GT(obs.m_g_px.x(), 52.5 - 31.5);  // barrel: the ideal point lies farther out
  const TargetObservation pinhole = measure_target(img.view(), camera, {0.5, 1.5, 10});
  EXPECT_DOUBLE_EQ(pinhole.m_g_px.x(), 52.5 - 31.5);
}

}  // namespace
}  // namespace avs::tracking
