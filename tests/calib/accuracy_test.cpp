// Issue 14, section 4: calibration accuracy against simulator ground truth, on three seeds.
// 16 board poses over 0.55-1.6 m, sensor noise 2 DN, distortion on both lenses, a projector turned
// and shifted off the paper's baseline; the same function as `avs calib bench` (no wall clock).
#include <cstdint>
#include <cstdio>

#include <gtest/gtest.h>

#include "avs/calib/bench.hpp"

namespace avs::calib {
namespace {

class CalibrationAccuracy : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(CalibrationAccuracy, SimulatedCaptureMeetsTheIssueTargets) {
  BenchConfig config;
  config.seed = GetParam();  // poses and sensor noise
  ASSERT_GE(config.views, 10);
  ASSERT_GT(config.noise_sigma_dn, 0);
  ASSERT_TRUE(config.truth.camera.has_distortion());
  ASSERT_TRUE(config.truth.projector.has_distortion());
  const BenchResult r = run_calibration_bench(config);
  std::printf("%s", summary_text(r.calibration).c_str());
  std::printf(
      "seed %llu: focal error %.3f %%, principal point error %.2f px, distortion difference "
      "%.2f px, baseline error %.3f mm, rotation error %.4f deg, plane depth RMS %.2f mm "
      "recovered / %.2f mm true = %.3f\n",
      static_cast<unsigned long long>(config.seed), r.focal_error_pct, r.principal_point_error_px,
      r.distortion_error_px, r.baseline_error_mm, r.rotation_error_deg, r.plane_rms_recovered_mm,
      r.plane_rms_true_mm, r.plane_rms_ratio);
  ASSERT_TRUE(r.calibration.accepted);
  EXPECT_EQ(r.calibration.views_used, config.views);
  // The issue's targets, on every seed:
  EXPECT_LE(r.focal_error_pct, 0.5);
  EXPECT_LE(r.principal_point_error_px, 2.0);
  EXPECT_LE(r.baseline_error_mm, 1.0);
  EXPECT_LE(r.rotation_error_deg, 0.1);
  EXPECT_LT(r.calibration.camera_rms_px, 0.3);
  EXPECT_LT(r.calibration.projector_rms_px, 0.5);
  EXPECT_LE(r.plane_rms_ratio, 1.2);
  // "Distortion within the noise": the worst pixel displacement difference over a 9 x 9 grid of
  // each whole image (the projector's outer image is never seen by the camera).
  EXPECT_LE(r.distortion_error_px, 4.0);
}

INSTANTIATE_TEST_SUITE_P(Seeds, CalibrationAccuracy, ::testing::Values(1u, 2u, 3u));

TEST(CalibrationRefusal, TooFewViewsAreRefusedWithAReason) {
  BenchConfig config;
  config.views = 4;
  const BenchResult r = run_calibration_bench(config);
  EXPECT_FALSE(r.calibration.accepted);
  ASSERT_FALSE(r.calibration.refusals.empty());
  EXPECT_NE(r.calibration.refusals[0].find("too few usable views: 4"), std::string::npos)
      << r.calibration.refusals[0];
}

TEST(CalibrationRefusal, ARmsThresholdBelowTheNoiseIsRefused) {
  BenchConfig config;
  config.views = 8;
  config.solve.min_views = 8;
  config.solve.max_projector_rms_px = 0.01;
  const BenchResult r = run_calibration_bench(config);
  EXPECT_FALSE(r.calibration.accepted);
  bool named = false;
  for (const std::string& why : r.calibration.refusals) {
    named = named || why.find("projector reprojection RMS") != std::string::npos;
  }
  EXPECT_TRUE(named) << summary_text(r.calibration);
}

}  // namespace
}  // namespace avs::calib
