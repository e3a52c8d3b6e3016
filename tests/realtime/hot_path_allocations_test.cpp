// Issue 16 section 3: no heap allocation per frame after warm-up in the hot paths of capture,
// decode, tracking, matching and the servo drive. This test program's malloc counts while a section
// is armed; the simulator renders the ken on the manipulator trajectory (head still) once, and 1000
// frames (500 depth maps) go through each core as the components run them: PatternSequencer (frame
// ids and timestamps of a GigE Vision camera -> labels, as the camera component), RollingDecoder
// (sub-code refinement on, as launch_config/closed_loop.yaml), image moments + servo law,
// MatchingPipeline with the closed loop's tuning; and 1000 cycles of the servo drive's DriveClient
// (command in, Modbus TCP exchange with both axes, safety, feedback out) against the simulated
// amplifiers on loopback.
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "ken_recording.hpp"

#include "avs/camera/pattern_sequencer.hpp"
#include "avs/decode/rolling_decoder.hpp"
#include "avs/matching/pipeline.hpp"
#include "avs/servo/amplifier_server.hpp"
#include "avs/servo/drive_client.hpp"
#include "avs/sim/simulator.hpp"
#include "avs/tracking/moments.hpp"
#include "avs/tracking/tracker.hpp"

namespace avs {
namespace {

using testing::CountAllocations;
using testing::recording;

constexpr int kWarmUpFrames = 108;  // 6 cycles: every buffer has reached its working size
constexpr int kCountedFrames = 1000;

decode::DecoderConfig closed_loop_decoder() {
  decode::DecoderConfig c;
  c.geometry = recording().config.renderer.geometry;
  c.subcode_half_window = 4;
  return c;
}

/// Runs frames [begin, end) through the decoder; calls on_depth(depth) for each depth map.
template <class OnDepth>
int decode_frames(decode::RollingDecoder& decoder, std::vector<float>& depth, int begin, int end,
                  OnDepth on_depth) {
  int maps = 0;
  for (int k = begin; k < end; ++k) {
    const decode::PatternFrame f = recording().frame(k);
    const decode::DecodeResult r = f.polarity == decode::Polarity::kNegative
                                       ? decoder.push_frame(f, depth)
                                       : decoder.push_frame(f);
    if (r.depth_updated) {
      ++maps;
      on_depth();
    }
  }
  return maps;
}

TEST(HotPathAllocations, CapturePatternSequencer) {
  // The camera component's per-frame core: label each frame from its id and timestamp, check
  // each pair's sum against the previous pair's (the camera buffer itself is lent, not copied:
  // docs/devices.md).
  camera::PatternSequencer sequencer{camera::SequencerConfig{}};
  long labelled = 0;
  const auto push = [&](int k) {
    camera::CameraFrame frame;
    frame.frame_id = static_cast<std::uint64_t>(k % 65535) + 1;  // GigE Vision ids: 0 skipped
    frame.timestamp_ns = 1'000'000LL * k;                        // 1000 fps
    frame.image = recording().frame(k).image;
    frame.token = static_cast<std::uint64_t>(k);
    const camera::Released released = sequencer.push(frame);
    for (int i = 0; i < released.count; ++i) {
      const camera::ReleasedFrame& f = released.frames[static_cast<std::size_t>(i)];
      labelled += f.reason == camera::DropReason::kNone ? 1 : 0;
    }
  };
  for (int k = 0; k < kWarmUpFrames; ++k) push(k);
  ASSERT_TRUE(sequencer.locked()) << "locked within " << kWarmUpFrames << " frames";
  labelled = 0;
  long allocations = 0;
  {
    CountAllocations counter;
    for (int k = kWarmUpFrames; k < kWarmUpFrames + kCountedFrames; ++k) push(k);
    allocations = counter.count();
  }
  EXPECT_GE(labelled, kCountedFrames - 2) << "labels over " << kCountedFrames << " frames";
  EXPECT_EQ(allocations, 0) << "over " << kCountedFrames << " frames";
}

TEST(HotPathAllocations, DecodeWithSubcodeRefinement) {
  decode::RollingDecoder decoder(closed_loop_decoder());
  std::vector<float> depth(decoder.config().geometry.camera.width *
                           decoder.config().geometry.camera.height);
  decode_frames(decoder, depth, 0, kWarmUpFrames, [] {});
  CountAllocations counter;
  const int maps =
      decode_frames(decoder, depth, kWarmUpFrames, kWarmUpFrames + kCountedFrames, [] {});
  const long allocations = counter.count();
  EXPECT_EQ(maps, kCountedFrames / 2);
  EXPECT_EQ(allocations, 0) << "over " << kCountedFrames << " frames";
}

TEST(HotPathAllocations, TrackingMomentsAndServoLaw) {
  decode::RollingDecoder decoder(closed_loop_decoder());
  const geometry::CameraModel& camera = decoder.config().geometry.camera;
  std::vector<float> depth(static_cast<std::size_t>(camera.width * camera.height));
  const geometry::DepthView view{depth.data(), camera.width, camera.height, 0};
  tracking::MomentsConfig moments;
  tracking::Tracker tracker{tracking::TrackerConfig{}};
  tracker.set_focal_lengths_px(camera.fx_px, camera.fy_px);
  int present = 0;
  const auto track = [&] {
    const tracking::TargetObservation obs = tracking::measure_target(view, camera, moments);
    present += obs.present ? 1 : 0;
    (void)tracker.update(obs, tracking::JointState{});
  };
  decode_frames(decoder, depth, 0, kWarmUpFrames, track);
  present = 0;
  // Only the tracking calls are counted (decode is the test above).
  long allocations = 0;
  decode_frames(decoder, depth, kWarmUpFrames, kWarmUpFrames + kCountedFrames, [&] {
    CountAllocations counter;
    track();
    allocations += counter.count();
  });
  EXPECT_GT(present, kCountedFrames / 4) << "the ken is in view";
  EXPECT_EQ(allocations, 0) << "over " << kCountedFrames / 2 << " depth maps";
}

TEST(HotPathAllocations, MatchingClosedLoopTuning) {
  decode::RollingDecoder decoder(closed_loop_decoder());
  const geometry::CameraModel& camera = decoder.config().geometry.camera;
  std::vector<float> depth(static_cast<std::size_t>(camera.width * camera.height));
  const geometry::DepthView view{depth.data(), camera.width, camera.height, 0};
  const matching::ObjectModel ken = matching::load_object_model("ken");
  matching::ModelCloudConfig model_config;
  model_config.target_points = ken.model_points;
  matching::PipelineConfig config;  // launch_config/closed_loop.yaml's matching parameters
  config.camera = camera;
  config.tracker.dense_icp_model = true;
  config.tracker.icp.max_correspondence_distance_m = 0.015F;
  config.scene.target_points = 500;
  config.scene.voxel_size_m = 0.005F;
  config.scene.outlier_neighbours = 8;
  config.tracker.icp.iterations = {0, 0, 2};
  config.lag_compensation_s = 0.009;
  config.velocity_window_s = 0.03;
  config.tracker.icp.metric = ken.metric;
  matching::MatchingPipeline pipeline(matching::make_model_cloud(ken.mesh, model_config), config);
  int stamp = 0, poses = 0;
  const auto match = [&] {
    const matching::PipelineOutput out = pipeline.process(view, 1e-3 * stamp, 0.009);
    stamp += 2;
    poses += out.has_pose ? 1 : 0;
  };
  decode_frames(decoder, depth, 0, kWarmUpFrames, match);
  poses = 0;
  long allocations = 0;
  long frames_allocating = 0;
  decode_frames(decoder, depth, kWarmUpFrames, kWarmUpFrames + kCountedFrames, [&] {
    CountAllocations counter;
    match();
    allocations += counter.count();
    frames_allocating += counter.count() > 0 ? 1 : 0;
  });
  EXPECT_GT(poses, kCountedFrames / 4) << "the ken is tracked";
  // Zero since the S-PCD outlier test searches a NeighbourGrid that keeps its buffers (the
  // nanoflann kd-tree before it mallocd its node pool on every build) and the pose history is
  // a vector, not a deque (which mallocd a block every few poses): 584 allocations before.
  std::printf("matching: %ld allocations over %d depth maps (%ld frames allocating)\n", allocations,
              kCountedFrames / 2, frames_allocating);
  EXPECT_EQ(allocations, 0) << "over " << kCountedFrames / 2 << " depth maps, " << frames_allocating
                            << " of them allocating";
}

TEST(HotPathAllocations, ServoDriveCycle) {
  // The servo_drive component's cycle: the newest torque command in (set_command), one
  // exchange per axis over Modbus TCP with every reply checked, the safety rules, the
  // feedback out (cycle into the component's reused CycleResult). The amplifiers answer on
  // their own thread (not counted); the test steps their plant between cycles.
  constexpr double kPeriodS = 1e-3;
  servo::AmplifierServer server{servo::AmplifierServerConfig{}};
  server.step(kPeriodS);
  servo::DriveClientConfig config = servo::default_drive_client_config("127.0.0.1", server.port());
  // Generous: a loaded machine must not turn a slow reply into a link fault (its message and
  // the reconnect allocate, as they may). The client's period must hold both timeouts; the
  // test's own clock still advances 1 ms a cycle.
  config.cycle_rate_hz = 2.0;
  config.response_timeout_s = 0.2;
  config.command_freshness.timeout_s = 10.0;
  servo::DriveClient client(config);
  client.connect();
  double t = 0;
  client.activate(t);
  const std::vector<double> torque_nm{0.002, -0.002};
  servo::CycleResult result;
  long healthy = 0;
  const auto cycle = [&](bool counted) {
    t += kPeriodS;
    long allocations = 0;
    {
      std::optional<CountAllocations> counter;
      if (counted) counter.emplace();
      (void)client.set_command(torque_nm, t, t);
      client.cycle(t, result);
      if (counter) allocations = counter->count();
    }
    healthy += result.link_ok && result.fault_message.empty() ? 1 : 0;
    server.step(kPeriodS);
    return allocations;
  };
  for (int i = 0; i < 100; ++i) (void)cycle(false);
  ASSERT_EQ(result.axes.size(), 2u);
  ASSERT_EQ(result.axes[0].state, servo::DriveState::operation_enabled);
  healthy = 0;
  long allocations = 0;
  for (int i = 0; i < kCountedFrames; ++i) allocations += cycle(true);
  EXPECT_EQ(healthy, kCountedFrames) << "every counted cycle exchanged with both axes";
  EXPECT_EQ(allocations, 0) << "over " << kCountedFrames << " cycles";
}

}  // namespace
}  // namespace avs
