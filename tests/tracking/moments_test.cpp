#include "avs/tracking/moments.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

// Eq. 7-9 written pixel by pixel (rows in order, each row's depths summed left to right, as
// the exact-sum contract says) on a full-size image of scattered target pixels, NaN, both
// infinities and depths outside the window, over regions whose edges do not fall on the 16-pixel
// blocks the implementation skips: the same moments, mean depth and bounds to the last bit.
TEST(Moments, EqualsTheDefinitionPixelByPixel) {
  constexpr int kSide = 512;
  std::vector<float> depth(kSide * kSide);
  std::uint32_t state = 12345;
  const auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / 16777216.0f;
  };
  const float inf = std::numeric_limits<float>::infinity();
  for (int v = 0; v < kSide; ++v) {
    for (int u = 0; u < kSide; ++u) {
      const float r = next();
      // Target pixels scattered (a few per block) and a dense patch; the rest is not target.
      const bool patch = u >= 200 && u < 263 && v >= 100 && v < 180;
      float z = 2.5f;
      if (patch || r < 0.02f)
        z = 0.6f + next();
      else if (r < 0.05f)
        z = nan_f;
      else if (r < 0.06f)
        z = inf;
      else if (r < 0.07f)
        z = -inf;
      depth[static_cast<std::size_t>(v) * kSide + u] = z;
    }
  }
  const geometry::DepthView view{depth.data(), kSide, kSide, 0};
  for (const PixelBox& region : {PixelBox{}, PixelBox{3, 300, 7, 411}, PixelBox{201, 262, 99, 181},
                                 PixelBox{17, 17, 0, 511}}) {
    MomentsConfig config{0.5, 1.5, 10, region};
    const TargetObservation obs = measure_target(view, camera, config);
    double m00 = 0, m10 = 0, m01 = 0, depth_sum = 0;
    PixelBox bounds{std::numeric_limits<int>::max(), -1, std::numeric_limits<int>::max(), -1};
    for (int v = std::max(0, region.v_min); v <= std::min(kSide - 1, region.v_max); ++v) {
      long count = 0, u_sum = 0;
      double row_depth = 0;
      for (int u = std::max(0, region.u_min); u <= std::min(kSide - 1, region.u_max); ++u) {
        const float h = depth[static_cast<std::size_t>(v) * kSide + u];
        if (!(0.5f < h && h < 1.5f)) continue;
        ++count;
        u_sum += u;
        row_depth += h;
        bounds.u_min = std::min(bounds.u_min, u);
        bounds.u_max = std::max(bounds.u_max, u);
        bounds.v_min = std::min(bounds.v_min, v);
        bounds.v_max = v;
      }
      m00 += static_cast<double>(count);
      m10 += static_cast<double>(u_sum) - camera.cx_px * static_cast<double>(count);
      m01 += (v - camera.cy_px) * static_cast<double>(count);
      depth_sum += row_depth;
    }
    ASSERT_GT(m00, 0);
    EXPECT_EQ(obs.m00, m00);
    EXPECT_EQ(obs.m10, m10);
    EXPECT_EQ(obs.m01, m01);
    EXPECT_EQ(obs.mean_depth_m, depth_sum / m00);
    EXPECT_EQ(obs.bounds.u_min, bounds.u_min);
    EXPECT_EQ(obs.bounds.u_max, bounds.u_max);
    EXPECT_EQ(obs.bounds.v_min, bounds.v_min);
    EXPECT_EQ(obs.bounds.v_max, bounds.v_max);
  }
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
