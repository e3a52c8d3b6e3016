// Object trajectories (see trajectory.hpp).
#include "avs/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace avs::sim {

double min_jerk(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * s * (10 + s * (-15 + 6 * s));
}

Twist twist_at(const Trajectory& trajectory, double t_s, double dt_s) {
  const Eigen::Isometry3d a = trajectory.T_world_object(t_s - dt_s);
  const Eigen::Isometry3d b = trajectory.T_world_object(t_s + dt_s);
  Twist twist;
  twist.v_world_mps = (b.translation() - a.translation()) / (2 * dt_s);
  const Eigen::AngleAxisd delta(b.linear() * a.linear().transpose());
  twist.w_world_rad_s = delta.axis() * delta.angle() / (2 * dt_s);
  return twist;
}

// ---------------------------------------------------------------- waypoints

WaypointTrajectory::WaypointTrajectory(std::vector<Waypoint> waypoints, bool ease, bool loop)
    : waypoints_(std::move(waypoints)), ease_(ease), loop_(loop) {
  if (waypoints_.empty()) throw std::invalid_argument("WaypointTrajectory: no waypoints");
  for (std::size_t i = 1; i < waypoints_.size(); ++i) {
    if (!(waypoints_[i].time_s > waypoints_[i - 1].time_s)) {
      throw std::invalid_argument("WaypointTrajectory: waypoint " + std::to_string(i) + " at " +
                                  std::to_string(waypoints_[i].time_s) + " s does not come after " +
                                  std::to_string(waypoints_[i - 1].time_s) + " s");
    }
  }
  for (Waypoint& w : waypoints_) w.q_world_object.normalize();
  if (loop_ && waypoints_.back().time_s <= 0) {
    throw std::invalid_argument("WaypointTrajectory: a loop needs a last waypoint after t = 0");
  }
}

Eigen::Isometry3d WaypointTrajectory::T_world_object(double t_s) const {
  if (loop_) {
    const double period = waypoints_.back().time_s;
    t_s = std::fmod(t_s, period);
    if (t_s < 0) t_s += period;
  }
  auto pose = [](const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = p;
    return T;
  };
  if (t_s <= waypoints_.front().time_s) {
    return pose(waypoints_.front().p_world_m, waypoints_.front().q_world_object);
  }
  if (t_s >= waypoints_.back().time_s) {
    return pose(waypoints_.back().p_world_m, waypoints_.back().q_world_object);
  }
  const auto next = std::upper_bound(waypoints_.begin(), waypoints_.end(), t_s,
                                     [](double t, const Waypoint& w) { return t < w.time_s; });
  const Waypoint& b = *next;
  const Waypoint& a = *(next - 1);
  double s = (t_s - a.time_s) / (b.time_s - a.time_s);
  if (ease_) s = min_jerk(s);
  return pose(a.p_world_m + s * (b.p_world_m - a.p_world_m),
              a.q_world_object.slerp(s, b.q_world_object));
}

// ---------------------------------------------------------------- manipulator (7.2.1)

Eigen::Isometry3d ManipulatorMotionConfig::default_start() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;  // columns: ken X -> world Y, ken Y -> world Z, ken Z -> world X
  R << 0, 0, 1,       //
      1, 0, 0,        //
      0, 1, 0;
  T.linear() = R;
  T.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  return T;
}

std::vector<RotationSegment> ManipulatorMotionConfig::paper_segments() {
  const double pi = std::numbers::pi;
  return {{Eigen::Vector3d::UnitZ(), pi / 2},
          {Eigen::Vector3d::UnitY(), pi / 4},
          {Eigen::Vector3d::UnitZ(), -pi / 4}};
}

ManipulatorTrajectory::ManipulatorTrajectory(ManipulatorMotionConfig config)
    : config_(std::move(config)) {
  double total_angle = 0;
  for (const RotationSegment& s : config_.segments) {
    if (s.axis_world.norm() < 1e-9) throw std::invalid_argument("ManipulatorTrajectory: zero axis");
    total_angle += std::abs(s.angle_rad);
  }
  if (!(config_.duration_s > 0) || !(total_angle > 0)) {
    throw std::invalid_argument("ManipulatorTrajectory: need a positive duration and angle");
  }
  double start = config_.start_time_s;
  for (const RotationSegment& s : config_.segments) {
    segment_start_s_.push_back(start);
    segment_duration_s_.push_back(config_.duration_s * std::abs(s.angle_rad) / total_angle);
    start += segment_duration_s_.back();
  }
}

Eigen::Isometry3d ManipulatorTrajectory::T_world_object(double t_s) const {
  const Eigen::Vector3d pivot =
      config_.T_world_object_start.translation() + config_.p_object_pivot_world_m;
  // Rotation about the pivot, accumulated over the segments done so far (world axes).
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  for (std::size_t i = 0; i < config_.segments.size(); ++i) {
    if (t_s <= segment_start_s_[i]) break;
    const double s = min_jerk((t_s - segment_start_s_[i]) / segment_duration_s_[i]);
    const RotationSegment& seg = config_.segments[i];
    R = Eigen::AngleAxisd(s * seg.angle_rad, seg.axis_world.normalized()).toRotationMatrix() * R;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R * config_.T_world_object_start.linear();
  T.translation() = pivot + R * (config_.T_world_object_start.translation() - pivot);
  return T;
}

// ---------------------------------------------------------------- lateral swing (7.1)

LateralSwingTrajectory::LateralSwingTrajectory(LateralSwingConfig config)
    : config_(std::move(config)) {
  if (!(config_.amplitude_m > 0) || !(config_.peak_speed_mps >= 0)) {
    throw std::invalid_argument("LateralSwingTrajectory: amplitude must be > 0, speed >= 0");
  }
  frequency_hz_ = config_.peak_speed_mps / (2 * std::numbers::pi * config_.amplitude_m);
  config_.axis_world.normalize();
}

Eigen::Isometry3d LateralSwingTrajectory::T_world_object(double t_s) const {
  const double t = std::max(0.0, t_s - config_.start_time_s);
  Eigen::Isometry3d T = config_.T_world_object_centre;
  T.translation() +=
      config_.axis_world * config_.amplitude_m * std::sin(2 * std::numbers::pi * frequency_hz_ * t);
  return T;
}

}  // namespace avs::sim
