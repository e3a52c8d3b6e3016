// Camera, projector and stereo calibration from the views' corners (OpenCV calibrateCamera and
// stereoCalibrate, inside solve.cpp only), giving the full model (K, distortion of both, R, t)
// from which the C and P of Eq. 4 follow (decode::SensorGeometry::camera_matrix() /
// projector_matrix()); a calibration that fails a check is refused with its reasons.
#pragma once

#include <string>
#include <vector>

#include "avs/calib/capture.hpp"
#include "avs/calib/observe.hpp"
#include "avs/decode/sensor_geometry.hpp"

namespace avs::calib {

struct SolveConfig {
  /// Refusals (docs/calibration.md says what each means and how to fix it).
  int min_views = 6;                      ///< usable views (board found, corners with codes)
  double min_view_corner_fraction = 0.7;  ///< a view needs this fraction of its corners decoded
  double max_camera_rms_px = 0.5;
  double max_projector_rms_px = 1.0;
  /// Fraction of a 4 x 4 grid over each image that the corners of all views reach.
  double min_coverage = 0.5;
  /// Of all corners of views with the board found, at most this fraction may lack codes
  /// (unstable codes: projector gamma, exposure, defocus).
  double max_undecoded_fraction = 0.3;
  /// A view whose board covers less than this fraction of the camera image is not used.
  double min_board_area_fraction = 0.005;
  /// Estimate k3 too (off: k3 = 0, the usual choice for moderate lenses and few views).
  bool estimate_k3 = false;
  /// Estimate the projector's k2 (off: k2 = k3 = 0). The camera sees only the middle of the
  /// projector's wider field, so the projector's outer image is never observed and k1 / k2
  /// trade off against each other; k1 and the tangential terms are always estimated.
  bool estimate_projector_k2 = false;
};

struct ViewReport {
  std::string name;
  bool used = false;
  std::string why_not;  ///< when not used
  int corners = 0;      ///< corners used
  double camera_rms_px = 0;
  double projector_rms_px = 0;
};

/// One used corner's reprojection through the final model: the board pose fitted to the
/// view's camera corners with the final camera lens (solvePnP), the projector through the
/// solved R, t. Residual = observed - predicted; a corner whose projector residual stands out
/// from its view's had an unstable decode (its window_fraction, homography_rms_px say why).
struct CornerError {
  std::string view;
  int index = 0;  ///< row-major inner-corner index
  Eigen::Vector2d camera_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d camera_residual_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d projector_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d projector_residual_px = Eigen::Vector2d::Zero();
  double window_fraction = 0;    ///< decode confidence (CornerObservation)
  double homography_rms_px = 0;  ///< decode confidence (CornerObservation)
};

struct CalibrationResult {
  /// True when every check passed; otherwise `refusals` says why (and geometry, if a solve
  /// was possible, is still filled for inspection, but must not be used).
  bool accepted = false;
  std::vector<std::string> refusals;
  decode::SensorGeometry geometry;
  double camera_rms_px = 0;     ///< over all used corners, final model
  double projector_rms_px = 0;  ///< over all used corners, final model
  double stereo_rms_px = 0;     ///< stereoCalibrate's own RMS (both images)
  double camera_coverage = 0;
  double projector_coverage = 0;
  double undecoded_fraction = 0;
  int views_used = 0;
  std::vector<ViewReport> views;
  std::vector<CornerError> corners;  ///< every used corner, when a solve was possible
};

/// Calibrates from the observations; never throws for bad data (it refuses instead).
CalibrationResult solve_calibration(const CaptureInfo& info,
                                    const std::vector<ViewObservation>& views,
                                    const SolveConfig& config = {});

/// The coverage picture: the corners of the used views over the camera's (or the
/// projector's) image, one 3 x 3 dot each, on the 4 x 4 grid the coverage check counts.
decode::GrayImage8 coverage_image(const CaptureInfo& info,
                                  const std::vector<ViewObservation>& views,
                                  const CalibrationResult& result, bool projector);

/// The per-corner errors as CSV (`corner_errors.csv` of `avs calib solve`'s report): a header
/// line, then one line per used corner.
std::string corner_errors_csv(const CalibrationResult& result);

/// A short text summary (per-view errors, figures, refusals).
std::string summary_text(const CalibrationResult& result);

}  // namespace avs::calib
