// Adapter (yaml-cpp, libpng): capture folders and board-pose files. The one capture format
// for every source (docs/calibration.md):
//
//   <dir>/index.yaml          what was captured (format, source, camera and projector sizes,
//                             the column and row codes, the rig's depth code layout, the
//                             board, the frame files of a view in order, the views)
//   <dir>/<view>/white.png    8-bit grey PNG per frame (FrameId::file_name())
//   <dir>/truth_calibration.yaml   simulator only: the true calibration (calibration format)
//
// Board-pose files (the simulator's poses, camera frame):
//   board: {squares_x: 10, squares_y: 7, square_m: 0.03, margin_m: 0.03}   # optional
//   poses:
//     - {xyz_m: [0.0, 0.0, 0.8], rpy_deg: [180, 10, 0]}
// Errors throw std::runtime_error naming the file and line.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "avs/calib/capture.hpp"

namespace avs::calib {

/// One view of an index: its folder name and, from the simulator, the board's true pose.
struct ViewEntry {
  std::string name;
  std::optional<Eigen::Isometry3d> T_camera_board_truth;
};

struct CaptureIndex {
  CaptureInfo info;
  std::vector<ViewEntry> views;
};

/// Writes (or rewrites) <dir>/index.yaml, and truth_calibration.yaml when info.truth is set.
/// Called after every view, so an interrupted capture still reads.
void write_capture_index(const std::filesystem::path& dir, const CaptureIndex& index);
/// Writes the view's frames to <dir>/<view.name>/.
void write_view_frames(const std::filesystem::path& dir, const BoardView& view,
                       const CaptureInfo& info);
CaptureIndex read_capture_index(const std::filesystem::path& dir);
/// Reads one view's frames (checked against the index: count and sizes).
BoardView read_view(const std::filesystem::path& dir, const ViewEntry& entry,
                    const CaptureInfo& info);

struct BoardPoses {
  sim::Checkerboard board;
  std::vector<Eigen::Isometry3d> T_camera_board;
};
BoardPoses load_board_poses_yaml(const std::string& path);
BoardPoses parse_board_poses_yaml(const std::string& text, const std::string& source_name);

}  // namespace avs::calib
