#include "avs/tracking/tracker.hpp"

#include <algorithm>

namespace avs::tracking {

std::string_view to_string(TrackingState state) {
  switch (state) {
    case TrackingState::idle:
      return "idle";
    case TrackingState::tracking:
      return "tracking";
    case TrackingState::lost:
      return "lost";
  }
  return "unknown";
}

Eigen::Vector2d Tracker::joint_pd(const Eigen::Vector2d& q_goal, const JointState& joints) const {
  Eigen::Vector2d tau = config_.hold_kp_nm_per_rad.cwiseProduct(q_goal - joints.q_rad) -
                        config_.hold_kv_nm_s_per_rad.cwiseProduct(joints.qd_rad_s);
  for (int i = 0; i < 2; ++i) {
    const double limit = config_.law.max_torque_nm[i];
    tau[i] = std::clamp(tau[i], -limit, limit);
  }
  return tau;
}

TrackerResult Tracker::update(const TargetObservation& observation, const JointState& joints) {
  TrackerResult out;
  out.target_present = observation.present;
  // 1. Count consecutive frames with / without a target.
  if (observation.present) {
    ++present_frames_;
    absent_frames_ = 0;
  } else {
    present_frames_ = 0;
    ++absent_frames_;
  }
  // 2. State transitions.
  const TrackingState before = state_;
  if (observation.present && present_frames_ >= config_.frames_to_track) {
    state_ = TrackingState::tracking;
  } else if (!observation.present && state_ == TrackingState::tracking) {
    state_ = TrackingState::lost;
  } else if (state_ == TrackingState::lost && absent_frames_ > config_.frames_to_idle) {
    state_ = TrackingState::idle;
  }
  if (state_ != before || !hold_valid_) {
    hold_q_rad_ = joints.q_rad;  // hold where the state was entered
    hold_valid_ = true;
  }
  // 3. Torque for the state.
  out.state = state_;
  if (state_ == TrackingState::tracking) {
    ServoLawInput in;
    in.m_g_px = observation.m_g_px;
    in.mean_depth_m = observation.mean_depth_m;
    in.q_rad = joints.q_rad;
    in.qd_rad_s = joints.qd_rad_s;
    const ServoLawResult law = servo_law(config_.law, in);  // Eq. 16
    out.torque_nm = law.torque_nm;
    out.error_px = law.error_px;
    out.saturated = law.saturated;
  } else if (state_ == TrackingState::idle && config_.idle == IdleBehaviour::return_home) {
    out.torque_nm = joint_pd(config_.home_q_rad, joints);
  } else {
    out.torque_nm = joint_pd(hold_q_rad_, joints);
  }
  return out;
}

}  // namespace avs::tracking
