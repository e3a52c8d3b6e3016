// Frame-to-frame tracking: initial alignment on the first observation, then ICP from the
// previous pose (optionally predicted at constant velocity), loss detection by RMSE and inlier
// ratio, re-initialisation after a loss.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>

#include "avs/matching/icp.hpp"
#include "avs/matching/initial_alignment.hpp"
#include "avs/matching/model_cloud.hpp"

namespace avs::matching {

struct TrackerConfig {
  /// Per-frame ICP: [0, 0, 1] as in the paper, point-to-plane (point-to-point on a few hundred
  /// model points keeps about a degree of bias, see docs/matching.md).
  IcpConfig icp = {.iterations = {0, 0, 1}, .metric = IcpMetric::point_to_plane};
  /// Per-frame ICP against the dense surface samples (ModelCloud::dense_points_m, exact mesh
  /// normals) instead of the M-PCD: the closest sample is then close to the closest surface
  /// point, which removes most of the sparse model's bias (docs/matching.md). The initial
  /// alignment still uses the M-PCD. Inlier distance and max_rmse_m default to the M-PCD's
  /// spacing either way.
  bool dense_icp_model = false;
  InitialAlignmentConfig initial;  ///< used on the first frame and after a loss
  bool constant_velocity = true;   ///< predict from the last two poses
  /// Above this ICP RMSE the frame fails (0 = the model's mean spacing). 15 mm: what every
  /// experiment runs with (the matching component's default).
  float max_rmse_m = 0.015F;
  float min_inlier_ratio = 0.3F;  ///< below this the frame is a failure (as the experiments)
  /// A frame that ran the initial alignment must reach this inlier ratio (issue 19, occlusion:
  /// with the target hidden, a sliver of it plus an occluder's edge aligned at 0.31-0.35 and
  /// flipped the pose; a whole target aligns at 0.8 and more).
  float min_initial_inlier_ratio = 0.6F;
  int failures_before_loss = 3;       ///< consecutive failures that declare the target lost
  std::size_t min_scene_points = 15;  ///< fewer: no update (counts as a failure)
  /// A target lost to missing data only (every failure that lost it had fewer than
  /// min_scene_points) whose last valid pose is at most this old (s) is first re-acquired by
  /// ICP from that pose, held to the initial alignment's inlier ratio; only when that fails
  /// does the initial alignment run. On a rig a dropped camera frame invalidates a bit for a
  /// whole cycle (n empty depth maps), and the initial alignment costs 10-40 ms against one
  /// ICP's 0.3 ms (docs/realtime.md). A target lost while its data was there (ICP failed: an
  /// occluder, a fast motion) re-initialises as before: re-acquiring those kept flipped poses
  /// (avs experiments occlusion, 1073 flipped updates). 0: off, every loss re-initialises
  /// (the paper's Sec. 6.1). A partly out-of-view target (MatchingPipeline::process,
  /// truncated) is forgotten, never re-acquired.
  double reacquire_within_s = 0.0;
};

enum class TrackingState { waiting, tracking, lost };

[[nodiscard]] const char* to_string(TrackingState state);

struct TrackResult {
  Eigen::Isometry3f T_camera_model = Eigen::Isometry3f::Identity();
  TrackingState state = TrackingState::waiting;
  bool initialised_this_frame = false;  ///< the initial alignment ran on this frame
  bool reacquired_this_frame = false;   ///< a lost target was found again from its last pose
  bool pose_valid = false;              ///< this frame passed the RMSE / inlier checks
  /// While tracking: how far the ICP pose is from the prediction it started from (NaN when
  /// there was none): the frame-to-frame jitter of the estimate beside its error.
  float rotation_from_prediction_deg = std::numeric_limits<float>::quiet_NaN();
  float translation_from_prediction_m = std::numeric_limits<float>::quiet_NaN();
  IcpResult icp;  ///< of this frame
};

class Tracker {
 public:
  Tracker(const ModelCloud& model, TrackerConfig config = {});

  /// One S-PCD (camera frame). stamp_s is used for the constant-velocity prediction.
  TrackResult update(const Points& p_camera, double stamp_s);

  /// Forget the target: the next frame runs the initial alignment.
  void reset();

  /// The per-frame checks from `config` (max_rmse_m, 0 = the model's spacing as at
  /// construction; min_inlier_ratio, failures_before_loss, min_scene_points,
  /// constant_velocity, reacquire_within_s), the state kept: what the matching component changes
  /// while it runs. The ICP and initial-alignment settings and the ICP model need a new Tracker.
  void retune(const TrackerConfig& config);

  [[nodiscard]] TrackingState state() const { return state_; }
  [[nodiscard]] const InitialAlignmentResult& last_initial_alignment() const {
    return last_initial_;
  }

 private:
  [[nodiscard]] Eigen::Isometry3f predict(double stamp_s) const;
  /// The frame passes: ICP valid, RMSE and inlier ratio (the initial alignment's when
  /// `as_initial`).
  [[nodiscard]] bool passes(const IcpResult& icp, bool as_initial) const;

  TrackerConfig config_;
  float default_max_rmse_m_ = 0.0F;  ///< what max_rmse_m 0 stands for (the model's spacing)
  Icp icp_;
  InitialAligner initial_;
  TrackingState state_ = TrackingState::waiting;
  int failures_ = 0;
  int absent_failures_ = 0;       ///< of failures_, frames with too few scene points
  bool lost_to_absence_ = false;  ///< every failure that lost the target was missing data
  std::optional<Eigen::Isometry3f> last_pose_;
  std::optional<Eigen::Isometry3f> previous_pose_;
  std::optional<Eigen::Isometry3f> last_valid_pose_;  ///< of the last frame that passed
  double last_valid_stamp_s_ = 0.0;
  double last_stamp_s_ = 0.0;
  double previous_stamp_s_ = 0.0;
  InitialAlignmentResult last_initial_;
};

}  // namespace avs::matching
