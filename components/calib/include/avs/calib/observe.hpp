// Per board view: the board's inner corners in the camera image (OpenCV's
// findChessboardCornersSB on the white frame, refined by cornerSubPix) and, for each, its projector
// coordinates from the decoded column and row Gray codes through a local homography around the
// corner (Moreno and Taubin, "Simple, Accurate, and Robust Projector-Camera Calibration", 3DIMPVT
// 2012, section 3). OpenCV is used inside observe.cpp only; this header has none of its types.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "avs/calib/capture.hpp"

namespace avs::calib {

struct ObserveConfig {
  /// Corners from findChessboardCornersSB are refined by cornerSubPix with a window of this
  /// half size (pixels), smaller where the squares are small; 0 or 1: no refinement.
  int max_subpixel_half_window_px = 5;
  /// A camera pixel is decoded when white - black >= this (DN): the projector lights it.
  int min_contrast_dn = 8;
  /// A bit counts as unstable at a pixel when |positive - negative| < this (DN); a pixel with
  /// an unstable bit is not used (stripe edges, where the camera pixel sees both polarities).
  int stable_bit_dn = 6;
  /// Half size (camera pixels) of the square window around a corner for the local homography.
  int window_half_px = 12;
  /// A corner gets projector coordinates when at least this fraction of its window decodes
  /// with stable bits, and the homography's inlier RMS is at most this many code widths
  /// (a code's quantisation alone gives 1 / sqrt(12) = 0.29).
  double min_window_fraction = 0.5;
  double max_homography_rms_codes = 0.6;
};

/// One inner corner of one view.
struct CornerObservation {
  int index = 0;  ///< row-major corner index (sim::Checkerboard::corner_board_m order)
  Eigen::Vector2d camera_px = Eigen::Vector2d::Zero();
  bool has_projector = false;
  Eigen::Vector2d projector_px = Eigen::Vector2d::Zero();
  /// Decode confidence: fraction of the window's pixels decoded with stable bits, the
  /// homography's inlier RMS (projector px) and its inlier count.
  double window_fraction = 0;
  double homography_rms_px = 0;
  int homography_inliers = 0;
};

struct ViewObservation {
  std::string name;
  bool board_found = false;
  std::vector<CornerObservation> corners;  ///< all inner corners when board_found
  int corners_with_projector() const;
  /// Area of the board's corner hull as a fraction of the camera image.
  double board_area_fraction = 0;
  /// Why the view is unusable (board not found, ...); empty when usable.
  std::string problem;
};

/// Corners, decoded codes and projector coordinates of one view.
ViewObservation observe_view(const BoardView& view, const CaptureInfo& info,
                             const ObserveConfig& config = {});

/// The camera corners of the white frame (findChessboardCornersSB, then cornerSubPix; see
/// ObserveConfig), in OpenCV's order. Empty when the board is not found.
std::vector<Eigen::Vector2d> find_board_corners(const decode::GrayImage8& white,
                                                const sim::Checkerboard& board,
                                                int max_subpixel_half_window_px = 5);

}  // namespace avs::calib
