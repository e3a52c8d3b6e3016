#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "avs/matching/pose_error.hpp"
#include "avs/matching/tracker.hpp"
#include "scene_fixture.hpp"

namespace avs::matching {
namespace {

// Paper 7.2.1: the ken turns pi/2 about Z, pi/4 about Y, then -pi/4 about Z within about 2 s,
// at up to about 1 m/s. Here: the same rotation sequence at 500 Hz, with the ken swept across
// the view.
Eigen::Isometry3f trajectory(double t_s) {
  const double phase = std::clamp(t_s / 2.0, 0.0, 1.0);
  const auto pi = std::numbers::pi;
  const double a = std::min(phase * 3.0, 1.0);
  const double b = std::clamp(phase * 3.0 - 1.0, 0.0, 1.0);
  const double c = std::clamp(phase * 3.0 - 2.0, 0.0, 1.0);
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  pose.linear() = (Eigen::AngleAxisd(-pi / 4 * c, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(pi / 4 * b, Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(pi / 2 * a, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(-pi / 2, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix()
                      .cast<float>();
  pose.translation() = Eigen::Vector3f(static_cast<float>(0.15 * std::sin(2.0 * pi * phase)),
                                       static_cast<float>(0.05 * std::sin(4.0 * pi * phase)), 0.6F);
  return pose;
}

struct TrackStats {
  int frames = 0, flips = 0, lost = 0;
  double position_rms_mm = 0, rotation_rms_deg = 0;
};

TrackStats follow_the_ken(const TrackerConfig& config) {
  const ObjectPreset ken = builtin_objects()[0];
  const ModelCloud model = test::model_of(ken);
  Tracker tracker(model, config);
  double squared_position = 0.0;
  double squared_rotation = 0.0;
  TrackStats out;
  for (int k = 0; k <= 1000; ++k) {
    const double t = k / 500.0;
    const Eigen::Isometry3f truth = trajectory(t);
    const Points scene = test::scene_of(ken, model, truth, static_cast<std::uint32_t>(k));
    const TrackResult result = tracker.update(scene, t);
    if (result.state != TrackingState::tracking) {
      ++out.lost;
      continue;
    }
    const PoseError error = pose_error(result.T_camera_model, truth, Symmetry::none);
    squared_position += static_cast<double>(error.translation_m * error.translation_m);
    squared_rotation += static_cast<double>(error.rotation_deg * error.rotation_deg);
    out.flips += error.rotation_deg > 90.0F ? 1 : 0;
    ++out.frames;
  }
  out.position_rms_mm = 1e3 * std::sqrt(squared_position / std::max(out.frames, 1));
  out.rotation_rms_deg = std::sqrt(squared_rotation / std::max(out.frames, 1));
  std::printf(
      "ken trajectory%s: %d frames tracked, position RMS %.2f mm, orientation RMS %.2f deg, %d "
      "flips\n",
      config.dense_icp_model ? " (dense ICP model)" : "", out.frames, out.position_rms_mm,
      out.rotation_rms_deg, out.flips);
  return out;
}

TEST(Tracker, FollowsTheKenTrajectoryAt500Hz) {
  const TrackStats r = follow_the_ken({});
  EXPECT_EQ(r.lost, 0);
  EXPECT_LE(r.position_rms_mm, 3.0);
  EXPECT_LE(r.rotation_rms_deg, 2.0);
  EXPECT_EQ(r.flips, 0);
}

// Per-frame ICP on the dense surface samples: the sparse M-PCD's bias goes (docs/matching.md).
TEST(Tracker, DenseIcpModelRemovesTheSparseModelsBias) {
  TrackerConfig dense;
  dense.dense_icp_model = true;
  const TrackStats sparse = follow_the_ken({});
  const TrackStats r = follow_the_ken(dense);
  EXPECT_EQ(r.lost, 0);
  EXPECT_EQ(r.flips, 0);
  EXPECT_LT(r.rotation_rms_deg, 0.7 * sparse.rotation_rms_deg);
  EXPECT_LT(r.position_rms_mm, sparse.position_rms_mm);
}

TEST(Tracker, DetectsLossAndReinitialises) {
  const ObjectPreset cube = builtin_objects()[1];
  const ModelCloud model = test::model_of(cube);
  TrackerConfig config;
  config.failures_before_loss = 2;
  Tracker tracker(model, config);
  const Eigen::Isometry3f first = random_object_pose(4);
  TrackResult result = tracker.update(test::scene_of(cube, model, first, 1), 0.0);
  EXPECT_TRUE(result.initialised_this_frame);
  EXPECT_EQ(result.state, TrackingState::tracking);
  result = tracker.update(test::scene_of(cube, model, first, 2), 0.002);
  EXPECT_FALSE(result.initialised_this_frame);
  EXPECT_EQ(result.state, TrackingState::tracking);

  // The cube jumps 9 cm to an unrelated pose: per-frame ICP cannot follow, the tracker declares
  // loss.
  Eigen::Isometry3f second = random_object_pose(99);
  second.translation() = first.translation() + Eigen::Vector3f(0.07F, -0.05F, 0.02F);
  for (int k = 0; k < 2; ++k) {
    result = tracker.update(test::scene_of(cube, model, second, 3 + static_cast<std::uint32_t>(k)),
                            0.004 + 0.002 * k);
    EXPECT_FALSE(result.pose_valid);
  }
  EXPECT_EQ(result.state, TrackingState::lost);

  // Next frame re-runs the initial alignment and finds the new pose.
  result = tracker.update(test::scene_of(cube, model, second, 7), 0.010);
  EXPECT_TRUE(result.initialised_this_frame);
  EXPECT_EQ(result.state, TrackingState::tracking);
  const PoseError error = pose_error(result.T_camera_model, second, Symmetry::cube);
  EXPECT_LT(error.rotation_deg, 5.0F);
  EXPECT_LT(error.translation_m, 0.005F);
}

// A gap in the data (a dropped camera frame leaves decode without a bit for a whole cycle: n
// empty depth maps) loses the target. Re-acquisition finds it again with one ICP from its last
// pose instead of an initial alignment; without it, or after a longer gap, the initial
// alignment runs.
struct GapOutcome {
  TrackResult after_gap;
  int lost_after = 0;  ///< frames after the gap not tracking
  PoseError error;
};

GapOutcome track_through_a_gap(double reacquire_within_s, double gap_s) {
  const ObjectPreset ken = builtin_objects()[0];
  const ModelCloud model = test::model_of(ken);
  TrackerConfig config;
  config.reacquire_within_s = reacquire_within_s;
  Tracker tracker(model, config);
  double t = 0.2;
  for (int k = 0; k < 50; ++k, t += 0.002) {
    const TrackResult r =
        tracker.update(test::scene_of(ken, model, trajectory(t), static_cast<std::uint32_t>(k)), t);
    EXPECT_EQ(r.state, TrackingState::tracking) << "before the gap, frame " << k;
  }
  const double last_valid_s = t - 0.002;
  for (; t < last_valid_s + gap_s - 1e-9; t += 0.002) {
    tracker.update(Points{}, t);  // the empty depth maps of the gap
  }
  EXPECT_EQ(tracker.state(), TrackingState::lost) << "3 empty frames in a row lose the target";
  GapOutcome out;
  out.after_gap = tracker.update(test::scene_of(ken, model, trajectory(t), 500), t);
  out.error = pose_error(out.after_gap.T_camera_model, trajectory(t), Symmetry::none);
  for (int k = 0; k < 50; ++k) {
    t += 0.002;
    const TrackResult r = tracker.update(
        test::scene_of(ken, model, trajectory(t), 600 + static_cast<std::uint32_t>(k)), t);
    out.lost_after += r.state == TrackingState::tracking ? 0 : 1;
  }
  return out;
}

TEST(Tracker, ReacquiresALostTargetFromItsLastPoseAfterAShortGapInTheData) {
  const GapOutcome r = track_through_a_gap(0.05, 0.018);  // 9 empty depth maps
  EXPECT_TRUE(r.after_gap.reacquired_this_frame);
  EXPECT_FALSE(r.after_gap.initialised_this_frame) << "no initial alignment needed";
  EXPECT_EQ(r.after_gap.state, TrackingState::tracking);
  EXPECT_LT(r.error.translation_m, 0.003F);
  EXPECT_LT(r.error.rotation_deg, 2.0F);
  EXPECT_EQ(r.lost_after, 0);
}

TEST(Tracker, WithoutReacquisitionOrAfterALongGapTheInitialAlignmentRuns) {
  const GapOutcome off = track_through_a_gap(0.0, 0.018);
  EXPECT_FALSE(off.after_gap.reacquired_this_frame);
  EXPECT_TRUE(off.after_gap.initialised_this_frame);
  const GapOutcome late = track_through_a_gap(0.05, 0.1);  // older than the window
  EXPECT_FALSE(late.after_gap.reacquired_this_frame);
  EXPECT_TRUE(late.after_gap.initialised_this_frame);
  EXPECT_EQ(late.after_gap.state, TrackingState::tracking);
}

// The cube tracked at `first` for two frames, re-acquisition on (1 s), loss after 2 failures;
// `elsewhere` is a pose 9 cm away that per-frame ICP cannot reach from `first`.
struct TrackedCube {
  ObjectPreset cube = builtin_objects()[1];
  ModelCloud model = test::model_of(cube);
  Tracker tracker{model, config()};
  Eigen::Isometry3f first = random_object_pose(4);
  Eigen::Isometry3f elsewhere = moved_away(first);

  static TrackerConfig config() {
    TrackerConfig c;
    c.failures_before_loss = 2;
    c.reacquire_within_s = 1.0;
    return c;
  }
  static Eigen::Isometry3f moved_away(const Eigen::Isometry3f& from) {
    Eigen::Isometry3f to = random_object_pose(99);
    to.translation() = from.translation() + Eigen::Vector3f(0.07F, -0.05F, 0.02F);
    return to;
  }
  TrackResult see(const Eigen::Isometry3f& pose, std::uint32_t seed, double t_s) {
    return tracker.update(test::scene_of(cube, model, pose, seed), t_s);
  }
  TrackedCube() {
    see(first, 1, 0.0);
    EXPECT_EQ(see(first, 2, 0.002).state, TrackingState::tracking);
  }
};

// Re-acquisition is held to the initial alignment's check: a target that is not where it was
// lost is not "found" near its old pose; the initial alignment finds where it is.
TEST(Tracker, ReacquisitionDoesNotAcceptATargetThatMovedAway) {
  TrackedCube t;
  t.tracker.update(Points{}, 0.004);
  t.tracker.update(Points{}, 0.006);
  ASSERT_EQ(t.tracker.state(), TrackingState::lost);
  const TrackResult result = t.see(t.elsewhere, 7, 0.008);
  EXPECT_FALSE(result.reacquired_this_frame);
  EXPECT_TRUE(result.initialised_this_frame);
  EXPECT_EQ(result.state, TrackingState::tracking);
  const PoseError error = pose_error(result.T_camera_model, t.elsewhere, Symmetry::cube);
  EXPECT_LT(error.rotation_deg, 5.0F);
  EXPECT_LT(error.translation_m, 0.005F);
}

// Only a target lost to missing data is re-acquired: one lost while its data was there (the ICP
// failed on it: an occluder, a jump) re-initialises, even when it comes back where it was (in
// the occlusion experiment re-acquiring those kept a flipped pose for seconds).
TEST(Tracker, ATargetLostWhileItsDataWasThereIsReinitialisedNotReacquired) {
  TrackedCube t;
  t.see(t.elsewhere, 3, 0.004);
  t.see(t.elsewhere, 4, 0.006);
  ASSERT_EQ(t.tracker.state(), TrackingState::lost);
  const TrackResult back = t.see(t.first, 5, 0.008);
  EXPECT_FALSE(back.reacquired_this_frame);
  EXPECT_TRUE(back.initialised_this_frame);
  EXPECT_EQ(back.state, TrackingState::tracking);
}

// The tracker reports how far each frame's ICP pose is from the constant-velocity prediction it
// started from (TrackResult::rotation_from_prediction_deg): the estimate's frame-to-frame jitter,
// which the accuracy runs print beside the error (docs/matching.md). On clean data it is the
// ken's own acceleration; a frame whose data is turned 10 deg pulls the ICP pose that far.
TEST(Tracker, ReportsHowFarEachPoseIsFromItsPrediction) {
  const ObjectPreset ken = builtin_objects()[0];
  const ModelCloud model = test::model_of(ken);
  Tracker tracker(model, {});
  float largest_clean_deg = 0, pulled_deg = 0;
  for (int k = 0; k < 120; ++k) {
    const double t = 0.2 + k / 500.0;
    Eigen::Isometry3f seen = trajectory(t);
    if (k == 100) {
      seen.linear() =
          Eigen::AngleAxisf(10.0F * std::numbers::pi_v<float> / 180.0F, Eigen::Vector3f::UnitX()) *
          seen.linear();
    }
    const TrackResult r =
        tracker.update(test::scene_of(ken, model, seen, static_cast<std::uint32_t>(k)), t);
    if (k == 0) {
      EXPECT_TRUE(std::isnan(r.rotation_from_prediction_deg)) << "no prediction on the first frame";
      EXPECT_TRUE(std::isnan(r.translation_from_prediction_m));
      continue;
    }
    ASSERT_TRUE(std::isfinite(r.rotation_from_prediction_deg)) << "frame " << k;
    ASSERT_TRUE(std::isfinite(r.translation_from_prediction_m)) << "frame " << k;
    if (k == 100) {
      pulled_deg = r.rotation_from_prediction_deg;
    } else if (k > 1 && k < 100) {
      largest_clean_deg = std::max(largest_clean_deg, r.rotation_from_prediction_deg);
    }
  }
  std::printf(
      "rotation from the prediction: at most %.2f deg on clean data, %.2f deg on the "
      "frame turned 10 deg\n",
      largest_clean_deg, pulled_deg);
  EXPECT_LT(largest_clean_deg, 3.0F);
  EXPECT_GT(pulled_deg, 5.0F);
}

}  // namespace
}  // namespace avs::matching
