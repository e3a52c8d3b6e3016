// The calibration's accuracy against simulator ground truth (issue 14, section 4): capture a
// seeded spread of board poses in the simulator with distortion on both lenses and a rotated
// projector, solve, and compare the result with the true calibration, and the depth of a
// plane decoded with the recovered calibration with the depth decoded with the true one.
// `avs calib bench` and the CTest accuracy test run this same function (no wall clock).
#pragma once

#include <cstdint>

#include "avs/calib/capture.hpp"
#include "avs/calib/observe.hpp"
#include "avs/calib/solve.hpp"

namespace avs::calib {

/// The true sensor of the bench: the paper's (decode::default_sensor_geometry()) with
/// distortion on both lenses, the principal points off centre and the projector turned and
/// shifted off the pure y baseline.
decode::SensorGeometry bench_truth_geometry();

struct BenchConfig {
  decode::SensorGeometry truth = bench_truth_geometry();
  sim::Checkerboard board;
  int views = 16;
  double near_m = 0.55;
  double far_m = 1.6;
  double max_tilt_deg = 30;
  std::uint64_t seed = 14;
  double noise_sigma_dn = 2.0;  ///< sensor noise per pixel and frame
  ObserveConfig observe;
  SolveConfig solve;
  double plane_distance_m = 1.0;
};

struct BenchResult {
  CalibrationResult calibration;
  double focal_error_pct = 0;           ///< worst of fx, fy of camera and projector
  double principal_point_error_px = 0;  ///< worst of cx, cy of camera and projector
  double distortion_error_px = 0;       ///< worst pixel displacement difference, both lenses
  double baseline_error_mm = 0;         ///< |t - t_true|
  double rotation_error_deg = 0;        ///< angle of R R_true^T
  double plane_rms_true_mm = 0;         ///< plane depth RMS decoded with the true calibration
  double plane_rms_recovered_mm = 0;    ///< ... with the recovered calibration
  double plane_rms_ratio = 0;           ///< recovered / true
};

/// Progress per view goes to `progress` when set (one line each).
BenchResult run_calibration_bench(const BenchConfig& config, std::FILE* progress = nullptr);

/// Depth RMS (mm) of a plane at `distance_m` rendered with `truth` and decoded with `decoder`.
double plane_depth_rms_mm(const decode::SensorGeometry& truth,
                          const decode::SensorGeometry& decoder, double distance_m);

}  // namespace avs::calib
