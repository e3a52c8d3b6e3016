// Capture folders and board-pose files (issue 14): a simulated view written and read back is
// the same, errors name the file and line.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "avs/calib/capture_folder.hpp"

namespace avs::calib {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::string& yaml) {
  try {
    parse_board_poses_yaml(yaml, "poses.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(CaptureFolder, AViewWrittenAndReadBackIsTheSame) {
  const fs::path dir = fs::temp_directory_path() / ("avs-capture-test-" + std::to_string(getpid()));
  fs::remove_all(dir);
  sim::RendererConfig renderer;
  renderer.geometry.camera.k1 = -0.05;
  SimCapture capture(renderer, sim::Checkerboard{});
  const Eigen::Isometry3d T = pose_from_xyz_rpy({0.02, -0.01, 0.8}, {185, 10, 5});
  const BoardView view = capture.render(T, 0, "pose_000");
  write_view_frames(dir, view, capture.info());
  write_capture_index(dir, {capture.info(), {{view.name, view.T_camera_board_truth}}});

  const CaptureIndex index = read_capture_index(dir);
  ASSERT_EQ(index.views.size(), 1u);
  EXPECT_EQ(index.info.source, "sim");
  EXPECT_EQ(index.info.codes.columns.bit_count, capture.info().codes.columns.bit_count);
  EXPECT_EQ(index.info.codes.rows.code_count, capture.info().codes.rows.code_count);
  EXPECT_EQ(index.info.depth_code_layout.first_row, renderer.geometry.layout.first_row);
  ASSERT_TRUE(index.info.truth.has_value());
  EXPECT_EQ(index.info.truth->camera, renderer.geometry.camera);
  ASSERT_TRUE(index.views[0].T_camera_board_truth.has_value());
  EXPECT_TRUE(index.views[0].T_camera_board_truth->isApprox(T, 1e-12));
  const BoardView back = read_view(dir, index.views[0], index.info);
  ASSERT_EQ(back.frames.size(), view.frames.size());
  for (std::size_t f = 0; f < view.frames.size(); ++f) {
    EXPECT_EQ(back.frames[f].pixels, view.frames[f].pixels) << f;
  }
  // A frame of the wrong size is an error naming the file.
  decode::write_png_gray8((dir / "pose_000" / "white.png").string(),
                          {4, 4, std::vector<std::uint8_t>(16)});
  try {
    read_view(dir, index.views[0], index.info);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("white.png: 4x4"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(CaptureFolder, BoardPoseFilesParseAndErrorsNameTheLine) {
  const BoardPoses poses = parse_board_poses_yaml(
      "board: {squares_x: 9, squares_y: 6, square_m: 0.025}\n"
      "poses:\n"
      "  - {xyz_m: [0, 0, 0.8], rpy_deg: [180, 0, 0]}\n"
      "  - {xyz_m: [0.1, 0, 1.2], rpy_deg: [170, 10, 5]}\n",
      "poses.yaml");
  EXPECT_EQ(poses.board.squares_x, 9);
  EXPECT_DOUBLE_EQ(poses.board.square_m, 0.025);
  ASSERT_EQ(poses.T_camera_board.size(), 2u);
  EXPECT_NEAR(poses.T_camera_board[1].translation().z(), 1.2, 1e-12);
  // The board faces the camera: its normal (+z) points along camera -z.
  EXPECT_NEAR(poses.T_camera_board[0].linear().col(2).z(), -1.0, 1e-12);

  EXPECT_NE(error_of("poses:\n  - {xyz_m: [0, 0], rpy_deg: [180, 0, 0]}\n").find("poses.yaml:2:"),
            std::string::npos);
  EXPECT_NE(
      error_of("poses:\n  - {xyz_m: [0, 0, 1], rpy: [180, 0, 0]}\n").find("unknown key 'rpy'"),
      std::string::npos);
  EXPECT_NE(error_of("board: {squares_x: 6, squares_y: 6}\nposes: []\n").find("must differ"),
            std::string::npos);
  EXPECT_NE(error_of("poses: []\n").find("non-empty"), std::string::npos);
}

}  // namespace
}  // namespace avs::calib
