// Object trajectories (issue 3 item 3): pose of an object in the world as a function of
// time. All are pure functions of t, so ground truth is exact at any instant.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Geometry>

namespace avs::sim {

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  virtual Eigen::Isometry3d T_world_object(double t_s) const = 0;
};

/// Linear and angular velocity (world frame) by central differences over +-dt_s.
struct Twist {
  Eigen::Vector3d v_world_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_world_rad_s = Eigen::Vector3d::Zero();
};
Twist twist_at(const Trajectory& trajectory, double t_s, double dt_s = 1e-4);

class StaticTrajectory final : public Trajectory {
 public:
  explicit StaticTrajectory(const Eigen::Isometry3d& T_world_object) : T_(T_world_object) {}
  Eigen::Isometry3d T_world_object(double) const override { return T_; }

 private:
  Eigen::Isometry3d T_;
};

struct Waypoint {
  double time_s = 0;
  Eigen::Vector3d p_world_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_object = Eigen::Quaterniond::Identity();
};

/// Piecewise interpolation between timed waypoints: position linearly, orientation by
/// slerp. With `ease` each segment follows the minimum-jerk profile 10s^3 - 15s^4 + 6s^5
/// (stops at every waypoint) instead of constant speed. Before the first and after the last
/// waypoint the pose holds; with `loop` the sequence repeats with period last.time_s.
class WaypointTrajectory final : public Trajectory {
 public:
  /// Throws std::invalid_argument unless there is at least one waypoint and times strictly
  /// increase.
  WaypointTrajectory(std::vector<Waypoint> waypoints, bool ease = false, bool loop = false);
  Eigen::Isometry3d T_world_object(double t_s) const override;

 private:
  std::vector<Waypoint> waypoints_;
  bool ease_, loop_;
};

/// One rotation of the manipulator motion: `angle_rad` about the world axis `axis_world`
/// through the pivot.
struct RotationSegment {
  Eigen::Vector3d axis_world = Eigen::Vector3d::UnitZ();
  double angle_rad = 0;
};

/// Section 7.2.1: the ken on a 7-DOF manipulator rotated about pi/2 about Z, pi/4 about Y,
/// then -pi/4 about Z, within about 2 s, peak speed about 1 m/s. Our parametrisation: the
/// rotations are about world axes through a pivot (the manipulator joint holding the ken)
/// and are applied one after another, each with a minimum-jerk profile; the total duration
/// is split in proportion to the angles. The pivot sits `p_object_pivot` from the object
/// origin; with the defaults the object is 0.34 m from the pivot's vertical axis, so the
/// first rotation (peak rate 1.875 x (pi/2) / 1 s = 2.95 rad/s) moves it at about 1 m/s.
struct ManipulatorMotionConfig {
  /// Start pose. Default: ken origin 1.0 m in front of the head (section 4.3's D), handle
  /// vertical (ken +Y = world +Z), crosspiece across the view (ken +X = world +Y), so the
  /// camera looks at the ken's -Z side.
  Eigen::Isometry3d T_world_object_start = default_start();
  /// Pivot relative to the object's start position, world axes: behind and below the ken.
  Eigen::Vector3d p_object_pivot_world_m = Eigen::Vector3d(0.34, 0.0, -0.15);
  std::vector<RotationSegment> segments = paper_segments();
  double start_time_s = 0.5;  ///< rest before the motion (initial alignment happens here)
  double duration_s = 2.0;    ///< all segments together ("about 2 s")

  static Eigen::Isometry3d default_start();
  static std::vector<RotationSegment> paper_segments();
};

class ManipulatorTrajectory final : public Trajectory {
 public:
  explicit ManipulatorTrajectory(ManipulatorMotionConfig config);
  Eigen::Isometry3d T_world_object(double t_s) const override;
  const ManipulatorMotionConfig& config() const { return config_; }

 private:
  ManipulatorMotionConfig config_;
  std::vector<double> segment_start_s_, segment_duration_s_;
};

/// Section 7.1: the ken on a rod swung laterally in front of the sensor. The object
/// oscillates along `axis_world` (default world Y: across the image) as A sin(2 pi f t),
/// with f chosen so that the peak speed A 2 pi f equals peak_speed_mps (the paper gives no
/// number; 7.1.2 shows the grip vanishing without tracking when swung "largely").
struct LateralSwingConfig {
  Eigen::Isometry3d T_world_object_centre = ManipulatorMotionConfig::default_start();
  Eigen::Vector3d axis_world = Eigen::Vector3d::UnitY();
  double amplitude_m = 0.25;
  double peak_speed_mps = 1.0;
  double start_time_s = 0.0;
};

class LateralSwingTrajectory final : public Trajectory {
 public:
  explicit LateralSwingTrajectory(LateralSwingConfig config);
  Eigen::Isometry3d T_world_object(double t_s) const override;
  double frequency_hz() const { return frequency_hz_; }
  const LateralSwingConfig& config() const { return config_; }

 private:
  LateralSwingConfig config_;
  double frequency_hz_ = 0;
};

/// Minimum-jerk blend 10s^3 - 15s^4 + 6s^5 of s clamped to [0, 1].
double min_jerk(double s);

}  // namespace avs::sim
