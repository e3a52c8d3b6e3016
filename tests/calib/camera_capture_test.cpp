// Issue 14, section 2: `avs calib capture --source camera` over the real protocol stacks. The
// simulator's board views are served by Aravis's GV fake camera (GVCP/GVSP on 127.0.0.1, the
// calibration sequence looping from an arbitrary phase, ids wrapping), CameraCapture reads them
// through AravisCamera and configures the projector (avs's DLPC350 emulator, byte-exact USB
// reports) with the calibration sequence. Every captured view must be the rendered view, byte
// for byte, in capture_frames() order; then the capture solves like a simulated one.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/calib/bench.hpp"
#include "avs/calib/camera_capture.hpp"
#include "avs/calib/solve.hpp"
#include "avs/projector/dlpc350_emulator.hpp"
#include "sim_gige_camera.hpp"

namespace avs::calib {
namespace {

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

TEST(CalibCameraCapture, ViewsOverGigEVisionAreTheRenderedFramesAndSolve) {
  const Rendered r;
  // Frame k of a projected cycle as an index into a view's frames (the three whites are one).
  std::vector<std::size_t> frame_of;
  for (std::size_t k = 0; k < kWhiteFrames; ++k) frame_of.push_back(0);
  for (std::size_t f = 1; f < r.views[0].frames.size(); ++f) frame_of.push_back(f);
  const std::size_t n = frame_of.size();
  std::atomic<int> showing{0};
  // The projector loops the sequence from frame 11 of a cycle when the camera starts.
  camera::SimGigECameraConfig served_config;
  served_config.frame_rate_hz = 200;
  served_config.first_frame_id = 65000;  // the 16-bit ids wrap during the capture
  camera::SimGigECamera served(served_config, r.info.camera_width, r.info.camera_height,
                               [&](std::uint64_t k, std::uint8_t* out) {
                                 const BoardView& view =
                                     r.views[static_cast<std::size_t>(showing.load())];
                                 const decode::GrayImage8& f = view.frames[frame_of[(k + 11) % n]];
                                 std::memcpy(out, f.pixels.data(), f.pixels.size());
                               });

  auto emulator = std::make_shared<projector::Dlpc350Emulator>(
      projector::EmulatorConfig{.flash_image_count = 3, .busy_reads = 1});
  CameraCaptureConfig config;
  config.camera.device_id = "127.0.0.1";
  config.camera.trigger_mode = camera::TriggerMode::kFreeRun;
  config.camera.frame_rate_hz = 200;
  config.camera.width = r.info.camera_width;
  config.camera.height = r.info.camera_height;
  projector::LinkConfig link;
  link.sequence = calibration_sequence(r.info.codes, 200, 1);
  config.projector = link;
  std::vector<std::string> log;
  CameraCapture capture(config, projector::emulator_opener(emulator), r.info.codes,
                        [&](const std::string& line) {
                          std::printf("%s\n", line.c_str());
                          log.push_back(line);
                        });
  std::printf("%s\n", capture.description().c_str());

  // The projector runs the calibration sequence: 38 patterns from flash images 1 and 2.
  EXPECT_TRUE(emulator->running());
  const std::vector<projector::PatternEntry> lut = emulator->pattern_lut();
  ASSERT_EQ(lut.size(), n);
  EXPECT_EQ(emulator->image_lut(), (std::vector<std::uint8_t>{1, 2}));

  std::vector<ViewObservation> observations;
  for (int v = 0; v < kViews; ++v) {
    showing = v;  // the board moved to the next pose
    const std::optional<BoardView> got = capture.capture_view("pose_" + std::to_string(v));
    ASSERT_TRUE(got) << "view " << v;
    EXPECT_EQ(got->name, "pose_" + std::to_string(v));
    ASSERT_EQ(got->frames.size(), r.views[static_cast<std::size_t>(v)].frames.size());
    for (std::size_t f = 0; f < got->frames.size(); ++f) {
      ASSERT_EQ(got->frames[f].pixels, r.views[static_cast<std::size_t>(v)].frames[f].pixels)
          << "view " << v << " frame " << f << " (" << capture_frames(r.info.codes)[f].file_name()
          << ")";
    }
    observations.push_back(observe_view(*got, r.info));
  }
  // What the camera gave solves as the simulator's own frames do.
  const CalibrationResult result = solve_calibration(r.info, observations, SolveConfig{});
  std::printf("%s", summary_text(result).c_str());
  EXPECT_TRUE(result.accepted);
  EXPECT_EQ(result.views_used, kViews);
  EXPECT_NEAR(result.geometry.camera.fx_px, r.info.truth->camera.fx_px,
              0.005 * r.info.truth->camera.fx_px);
}

TEST(CalibCameraCapture, NoSequenceOnTheCameraEndsTheViewWithTheReason) {
  const Rendered r;
  camera::SimGigECameraConfig served_config;
  served_config.frame_rate_hz = 200;
  // The projector is dark: the camera sees the black frame only.
  camera::SimGigECamera served(served_config, r.info.camera_width, r.info.camera_height,
                               [&](std::uint64_t, std::uint8_t* out) {
                                 const decode::GrayImage8& f = r.views[0].frames[1];
                                 std::memcpy(out, f.pixels.data(), f.pixels.size());
                               });
  CameraCaptureConfig config;
  config.camera.device_id = "127.0.0.1";
  config.camera.trigger_mode = camera::TriggerMode::kFreeRun;
  config.camera.frame_rate_hz = 200;
  config.view_timeout = std::chrono::milliseconds(1500);
  std::vector<std::string> log;
  CameraCapture capture(config, {}, r.info.codes,
                        [&](const std::string& line) { log.push_back(line); });
  EXPECT_NE(capture.description().find("not controlled"), std::string::npos);
  EXPECT_FALSE(capture.capture_view("dark"));
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.back().find("calibration sequence"), std::string::npos) << log.back();
}

TEST(CalibCameraCapture, AProjectorThatRefusesTheSequenceStopsTheCaptureWithItsWords) {
  const Rendered r;
  // Only one flash image: the calibration sequence's second image is not there.
  auto emulator = std::make_shared<projector::Dlpc350Emulator>(
      projector::EmulatorConfig{.flash_image_count = 1, .busy_reads = 1});
  CameraCaptureConfig config;
  config.camera.device_id = "127.0.0.1";
  projector::LinkConfig link;
  link.sequence = calibration_sequence(r.info.codes, 200, 0);
  config.projector = link;
  try {
    CameraCapture capture(config, projector::emulator_opener(emulator), r.info.codes,
                          [](const std::string&) {});
    FAIL() << "started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("refused the calibration sequence"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace avs::calib
