#include "avs/matching/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "avs/matching/pose_error.hpp"

namespace avs::matching {

const char* to_string(TrackingState state) {
  switch (state) {
    case TrackingState::waiting:
      return "waiting";
    case TrackingState::tracking:
      return "tracking";
    case TrackingState::lost:
      return "lost";
  }
  return "unknown";
}

namespace {

IcpConfig icp_config(const ModelCloud& model, const TrackerConfig& config) {
  IcpConfig icp = config.icp;
  // Dense samples are ~2 mm apart: keep the inlier test at the M-PCD's spacing.
  if (config.dense_icp_model && !(icp.inlier_distance_m > 0.0F) && model.mean_spacing_m > 0.0F)
    icp.inlier_distance_m = model.mean_spacing_m;
  return icp;
}

bool use_dense(const ModelCloud& model, const TrackerConfig& config) {
  return config.dense_icp_model && model.dense_points_m.size() >= 3 &&
         model.dense_normals.size() == model.dense_points_m.size();
}

}  // namespace

Tracker::Tracker(const ModelCloud& model, TrackerConfig config)
    : config_(config),
      icp_(use_dense(model, config) ? model.dense_points_m : model.points_m,
           icp_config(model, config),
           use_dense(model, config) ? model.dense_normals : model.normals),
      initial_(model, config.initial) {
  if (config_.dense_icp_model && !use_dense(model, config)) {
    throw std::invalid_argument(
        "Tracker: dense_icp_model needs ModelCloud::dense_points_m with normals (got " +
        std::to_string(model.dense_points_m.size()) + " points, " +
        std::to_string(model.dense_normals.size()) + " normals)");
  }
  default_max_rmse_m_ = config_.dense_icp_model && model.mean_spacing_m > 0.0F
                            ? model.mean_spacing_m
                            : icp_.model_spacing_m();
  if (!(config_.max_rmse_m > 0.0F)) config_.max_rmse_m = default_max_rmse_m_;
}

void Tracker::retune(const TrackerConfig& config) {
  config_.max_rmse_m = config.max_rmse_m > 0.0F ? config.max_rmse_m : default_max_rmse_m_;
  config_.min_inlier_ratio = config.min_inlier_ratio;
  config_.failures_before_loss = config.failures_before_loss;
  config_.min_scene_points = config.min_scene_points;
  config_.constant_velocity = config.constant_velocity;
  config_.reacquire_within_s = config.reacquire_within_s;
}

void Tracker::reset() {
  state_ = TrackingState::waiting;
  failures_ = 0;
  absent_failures_ = 0;
  lost_to_absence_ = false;
  last_pose_.reset();
  previous_pose_.reset();
  last_valid_pose_.reset();
}

bool Tracker::passes(const IcpResult& icp, bool as_initial) const {
  const float min_inliers =
      as_initial ? std::max(config_.min_inlier_ratio, config_.min_initial_inlier_ratio)
                 : config_.min_inlier_ratio;
  return icp.valid && icp.rmse_m <= config_.max_rmse_m && icp.inlier_ratio() >= min_inliers;
}

Eigen::Isometry3f Tracker::predict(double stamp_s) const {
  if (!config_.constant_velocity || !previous_pose_ || last_stamp_s_ <= previous_stamp_s_)
    return *last_pose_;
  // Constant velocity: apply the last inter-frame motion, scaled to the elapsed time.
  const Eigen::Isometry3f delta = *last_pose_ * previous_pose_->inverse();
  const double scale = (stamp_s - last_stamp_s_) / (last_stamp_s_ - previous_stamp_s_);
  if (!(scale > 0.0) || scale > 4.0) return *last_pose_;
  const Eigen::AngleAxisf rotation(delta.linear());
  Eigen::Isometry3f scaled = Eigen::Isometry3f::Identity();
  scaled.linear() = Eigen::AngleAxisf(rotation.angle() * static_cast<float>(scale), rotation.axis())
                        .toRotationMatrix();
  scaled.translation() = delta.translation() * static_cast<float>(scale);
  return scaled * *last_pose_;
}

TrackResult Tracker::update(const Points& p_camera, double stamp_s) {
  TrackResult result;
  if (p_camera.size() < config_.min_scene_points) {
    if (state_ == TrackingState::tracking) {
      ++absent_failures_;
      if (++failures_ >= config_.failures_before_loss) {
        state_ = TrackingState::lost;
        lost_to_absence_ = absent_failures_ == failures_;
      }
    }
    result.state = state_;
    if (last_pose_) result.T_camera_model = *last_pose_;
    return result;
  }

  // 1. Pose guess: when not tracking, re-acquisition from the last valid pose (when recent)
  //    or else the initial alignment; when tracking, the prediction from the last poses.
  bool as_initial = false;                      // held to the initial alignment's inlier ratio
  std::optional<Eigen::Isometry3f> prediction;  // while tracking: the ICP's start
  if (state_ != TrackingState::tracking) {
    as_initial = true;
    previous_pose_.reset();  // no velocity across a loss
    const double since_valid_s = stamp_s - last_valid_stamp_s_;
    if (state_ == TrackingState::lost && lost_to_absence_ && last_valid_pose_ &&
        config_.reacquire_within_s > 0.0 && since_valid_s >= 0.0 &&
        since_valid_s <= config_.reacquire_within_s) {
      IcpResult icp = icp_.align(p_camera, *last_valid_pose_);
      if (passes(icp, true)) {
        result.reacquired_this_frame = true;
        result.icp = std::move(icp);
      } else {
        lost_to_absence_ = false;  // not where it was lost: initial alignments from now on
      }
    }
    if (!result.reacquired_this_frame) {
      last_initial_ = initial_.align(p_camera);
      result.initialised_this_frame = true;
      if (!last_initial_.valid) {
        result.state = state_;
        return result;
      }
      // 2. Fixed-count ICP from the guess.
      result.icp = icp_.align(p_camera, last_initial_.T_camera_model);
    }
  } else {
    // 2. Fixed-count ICP from the guess.
    prediction = predict(stamp_s);
    result.icp = icp_.align(p_camera, *prediction);
  }
  result.T_camera_model = result.icp.T_camera_model;
  result.pose_valid = passes(result.icp, as_initial);
  if (prediction) {
    const PoseError step = pose_error(result.T_camera_model, *prediction, Symmetry::none);
    result.rotation_from_prediction_deg = step.rotation_deg;
    result.translation_from_prediction_m = step.translation_m;
  }

  // 3. State machine: failures in a row declare the target lost; a lost target re-initialises.
  if (result.pose_valid) {
    failures_ = 0;
    absent_failures_ = 0;
    lost_to_absence_ = false;
    state_ = TrackingState::tracking;
    last_valid_pose_ = result.T_camera_model;
    last_valid_stamp_s_ = stamp_s;
    previous_pose_ = last_pose_;
    previous_stamp_s_ = last_stamp_s_;
    last_pose_ = result.T_camera_model;
    last_stamp_s_ = stamp_s;
    if (result.reacquired_this_frame) previous_pose_.reset();  // no velocity across the gap
  } else if (state_ == TrackingState::tracking) {
    if (++failures_ >= config_.failures_before_loss) {
      state_ = TrackingState::lost;
      lost_to_absence_ = false;  // the data was there and did not fit: re-initialise
      previous_pose_.reset();
    } else {
      previous_pose_ = last_pose_;
      previous_stamp_s_ = last_stamp_s_;
      last_pose_ = result.T_camera_model;
      last_stamp_s_ = stamp_s;
    }
  } else {
    state_ = TrackingState::lost;
    lost_to_absence_ = false;  // a re-acquisition or initial alignment failed: start afresh
  }
  result.state = state_;
  return result;
}

}  // namespace avs::matching
