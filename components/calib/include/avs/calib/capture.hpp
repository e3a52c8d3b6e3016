// Projector-camera calibration captures (issue 14, section 2): what is projected per board
// pose (white, black, column and row Gray codes, positive and negative), the captured views,
// and the simulator as a capture source. Plain C++/Eigen, no I/O (capture_folder.hpp writes
// and reads capture folders).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "avs/decode/gray_code.hpp"
#include "avs/decode/png_io.hpp"
#include "avs/decode/sensor_geometry.hpp"
#include "avs/sim/checkerboard.hpp"
#include "avs/sim/renderer.hpp"

namespace avs::calib {

enum class FrameKind : std::uint8_t { kWhite, kBlack, kColumnBit, kRowBit };

/// One projected frame of a view.
struct FrameId {
  FrameKind kind = FrameKind::kWhite;
  int bit = 0;  ///< 0 = MSB (Eq. 1); column and row bits only
  bool positive = true;
  /// File name in a capture folder: white.png, black.png, column_03_pos.png, row_10_neg.png.
  std::string file_name() const;
  /// The same without ".png": white, column_03_pos.
  std::string label() const;
};

/// The calibration codes over the projector's DMD: Gray codes of its columns and of its rows
/// (CodeLayout's "rows" are columns for the column code).
struct CaptureCodes {
  int projector_width = 0;
  int projector_height = 0;
  decode::CodeLayout columns;
  decode::CodeLayout rows;
};

/// Codes of `pixels_per_code` DMD columns (rows) each. The default 4 makes the finest stripe
/// about 2 camera pixels wide in the paper's rig (a projector pixel is ~0.6 camera pixels):
/// finer stripes blur together in the camera and their bits, mixed, bias the decoded position
/// (measured in the simulator: up to 0.25 projector px per view with 1-pixel codes and a
/// distorted camera); the local homography averages the coarser quantisation instead.
CaptureCodes calibration_codes(int projector_width, int projector_height, int pixels_per_code = 4);

/// The frames of one view in capture order: white, black, then per column bit positive and
/// negative, then per row bit positive and negative.
std::vector<FrameId> capture_frames(const CaptureCodes& codes);

/// The images of one board pose, in capture_frames() order.
struct BoardView {
  std::string name;
  std::vector<decode::GrayImage8> frames;
  /// Simulator only: the board's true pose (board frame, see sim::Checkerboard).
  std::optional<Eigen::Isometry3d> T_camera_board_truth;
};

/// What a capture is, apart from its images.
struct CaptureInfo {
  std::string source = "sim";
  sim::Checkerboard board;
  int camera_width = 0;
  int camera_height = 0;
  CaptureCodes codes;
  /// The rig's 500 Hz row code, written into the calibration file's code_layout.
  decode::CodeLayout depth_code_layout;
  /// Simulator only: the true calibration.
  std::optional<decode::SensorGeometry> truth;
};

/// The simulator as a capture source: the board at any pose in front of the simulated rig.
class SimCapture {
 public:
  /// `renderer.geometry` is the true calibration (any lenses, any projector pose);
  /// its layout becomes CaptureInfo::depth_code_layout.
  SimCapture(const sim::RendererConfig& renderer, const sim::Checkerboard& board,
             int pixels_per_code = 4);

  const CaptureInfo& info() const { return info_; }
  /// Renders every frame of one view (noise keys from `view_index`, so each view and frame
  /// has its own noise, the same on every run).
  BoardView render(const Eigen::Isometry3d& T_camera_board, int view_index,
                   const std::string& name);

 private:
  CaptureInfo info_;
  sim::Renderer renderer_;
  geometry::Mesh mesh_;
};

/// Where a board pose is seen from: the fraction of the board's inner corners inside the
/// camera and inside the projector image (with a margin of `margin_px`); both 0 when a corner
/// of the plate itself is outside either image.
struct PoseVisibility {
  double camera = 0;
  double projector = 0;
};
PoseVisibility pose_visibility(const decode::SensorGeometry& geometry,
                               const sim::Checkerboard& board,
                               const Eigen::Isometry3d& T_camera_board, double margin_px = 10);

/// A seeded spread of `count` board poses over [near_m, far_m] (board centre z, evenly
/// stratified; centres towards the 3 x 3 regions of the camera image in turn), tilted up to
/// `max_tilt_deg` about the board's x and y axes and turned up to 20 deg about its normal, placed
/// where the whole board is in view of the camera and the projector. Deterministic for a seed on
/// every platform (own uniform generator). Throws if a pose cannot be placed (the board does not
/// fit the views at near_m).
std::vector<Eigen::Isometry3d> generate_board_poses(const decode::SensorGeometry& geometry,
                                                    const sim::Checkerboard& board, int count,
                                                    double near_m, double far_m,
                                                    double max_tilt_deg, std::uint64_t seed);

/// A board pose from position (m) and roll-pitch-yaw (deg, applied as Rz(yaw) Ry(pitch)
/// Rx(roll)); a board facing the camera has roll 180.
Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, const Eigen::Vector3d& rpy_deg);

}  // namespace avs::calib
