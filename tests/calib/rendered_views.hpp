// Simulated board views for the capture-source tests (camera, bag): the bench's sensor, 8 poses
// of a seeded spread over 0.55-1.6 m, 2 DN noise, rendered once per test program.
#pragma once

#include <string>
#include <vector>

#include "avs/calib/bench.hpp"
#include "avs/calib/view_assembler.hpp"

namespace avs::calib::test {

constexpr int kViews = 8;

struct Rendered {
  Rendered() {
    sim::RendererConfig renderer;
    renderer.geometry = bench_truth_geometry();
    renderer.noise_sigma_dn = 2.0;
    SimCapture capture(renderer, board);
    info = capture.info();
    const auto poses = generate_board_poses(renderer.geometry, board, kViews, 0.55, 1.6, 30, 7);
    for (int v = 0; v < kViews; ++v) {
      views.push_back(
          capture.render(poses[static_cast<std::size_t>(v)], v, "pose_" + std::to_string(v)));
    }
  }
  sim::Checkerboard board;
  CaptureInfo info;
  std::vector<BoardView> views;
};

inline const Rendered& rendered() {
  static const Rendered r;
  return r;
}

/// Frame k of a projected cycle (projection_sequence) as an index into a view's frames: the
/// white frames are all frame 0.
inline std::vector<std::size_t> projected_frame_of(const BoardView& view) {
  std::vector<std::size_t> frame_of(kWhiteFrames, 0);
  for (std::size_t f = 1; f < view.frames.size(); ++f) frame_of.push_back(f);
  return frame_of;
}

}  // namespace avs::calib::test
