// Tracking states around the servo law (issue 5 item 2):
//   idle     - no target: hold the current pose, or return home;
//   tracking - target present for `frames_to_track` consecutive frames: Eq. 16;
//   lost     - target gone while tracking: hold where it was lost for `frames_to_idle`
//              frames (so a brief dropout does not send the head home), then idle.
// One update() per observation (500 Hz); pure, no clock of its own.
#pragma once

#include <cstdint>
#include <string_view>

#include "avs/tracking/moments.hpp"
#include "avs/tracking/servo_law.hpp"

namespace avs::tracking {

enum class TrackingState : std::uint8_t { idle, tracking, lost };
std::string_view to_string(TrackingState state);

enum class IdleBehaviour : std::uint8_t { hold, return_home };

struct TrackerConfig {
  ServoLawConfig law;
  int frames_to_track = 3;   ///< N consecutive frames with a target before tracking
  int frames_to_idle = 100;  ///< frames without target in lost before idle (0.2 s at 500 Hz)
  IdleBehaviour idle = IdleBehaviour::hold;
  Eigen::Vector2d home_q_rad = Eigen::Vector2d::Zero();
  Eigen::Vector2d hold_kp_nm_per_rad = {2.0, 0.3};  ///< joint PD for hold / home
  Eigen::Vector2d hold_kv_nm_s_per_rad = {0.1, 0.015};
};

struct JointState {
  Eigen::Vector2d q_rad = Eigen::Vector2d::Zero();
  Eigen::Vector2d qd_rad_s = Eigen::Vector2d::Zero();
};

struct TrackerResult {
  TrackingState state = TrackingState::idle;
  Eigen::Vector2d torque_nm = Eigen::Vector2d::Zero();
  Eigen::Vector2d error_px = Eigen::Vector2d::Zero();  ///< m_d - m_g while tracking, else 0
  bool target_present = false;
  bool saturated = false;
};

class Tracker {
 public:
  explicit Tracker(TrackerConfig config) : config_(std::move(config)) {}

  TrackerResult update(const TargetObservation& observation, const JointState& joints);

  TrackingState state() const { return state_; }
  const TrackerConfig& config() const { return config_; }
  /// The servo law's focal lengths (Eq. 15), from the camera model in force.
  void set_focal_lengths_px(double fx_px, double fy_px) {
    config_.law.fx_px = fx_px;
    config_.law.fy_px = fy_px;
  }
  void reset() { *this = Tracker(config_); }
  /// New gains, limits and state thresholds from the next update on (a parameter changed while
  /// running); the tracking state and the focal lengths in force stay.
  void retune(TrackerConfig config) {
    config.law.fx_px = config_.law.fx_px;
    config.law.fy_px = config_.law.fy_px;
    config_ = std::move(config);
  }

 private:
  Eigen::Vector2d joint_pd(const Eigen::Vector2d& q_goal, const JointState& joints) const;

  TrackerConfig config_;
  TrackingState state_ = TrackingState::idle;
  int present_frames_ = 0;
  int absent_frames_ = 0;
  bool hold_valid_ = false;
  Eigen::Vector2d hold_q_rad_ = Eigen::Vector2d::Zero();
};

}  // namespace avs::tracking
