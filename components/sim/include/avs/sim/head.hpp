// Pan/tilt head kinematics (paper section 3.2, Figure 3; offset `a` of Eq. 15): where the
// camera (and the projector rigidly fixed to it) is for given joint angles.
//
// World frame (ours): origin on the pan axis, Z up, X the viewing direction at zero pan and
// tilt, Y to the left. Pan q_pan rotates about world Z (positive turns the view to the left);
// tilt q_tilt then rotates about the pan-rotated Y axis (positive tilts the view down).
// The camera frame is the optical one of decode::SensorGeometry (x right, y down, z forward).
#pragma once

#include <Eigen/Geometry>

namespace avs::sim {

struct HeadConfig {
  /// Pan axis foot point in the world (default: the world origin).
  Eigen::Vector3d p_world_pan_m = Eigen::Vector3d::Zero();
  /// Tilt axis point in the pan-rotated frame (X forward, Y left, Z up); default on the pan
  /// axis (orthogonal intersecting axes, Figure 3).
  Eigen::Vector3d p_pan_tilt_m = Eigen::Vector3d::Zero();
  /// Camera optical centre in the tilt-rotated frame; x is Eq. 15's `a` (along the optical
  /// axis from the tilt axis). 40 mm is our assumption (shared/reference/servo-modbus-cia402.md
  /// puts the camera 40 mm off the tilt axis); the paper gives no number.
  Eigen::Vector3d p_tilt_camera_m = Eigen::Vector3d(0.04, 0.0, 0.0);
};

/// Joint angles and rates at one instant.
struct HeadState {
  double pan_rad = 0;
  double tilt_rad = 0;
  double pan_rate_rad_s = 0;
  double tilt_rate_rad_s = 0;
};

/// Rotation from the camera optical frame to the head frame (X forward, Y left, Z up).
Eigen::Matrix3d R_head_optical();

/// T_world_camera(q_pan, q_tilt): Rz(q_pan) * T(p_pan_tilt) * Ry(q_tilt) * T(p_tilt_camera) *
/// R_head_optical, after translating by p_world_pan.
Eigen::Isometry3d T_world_camera(const HeadConfig& head, double pan_rad, double tilt_rad);

/// Joint angles that point the optical axis at p_world, ignoring the camera offsets (exact
/// when all offsets are zero); handy for aiming the head at a target in tests and scenes.
HeadState look_at(const HeadConfig& head, const Eigen::Vector3d& p_world);

}  // namespace avs::sim
