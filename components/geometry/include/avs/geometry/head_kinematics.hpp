// Pan/tilt head kinematics (paper section 3.2, Figure 3; offset `a` of Eq. 15): where the
// camera (and the projector rigidly fixed to it) is for given joint angles.
//
// Sign convention: the servo one of docs/servo.md section 1 (Eq. 15's J = diag(-f cos q2, -f)).
// Joint angles q = [q1 pan, q2 tilt] in output-side radians; positive q1 turns the optical axis
// toward image +x (right), positive q2 toward image +y (down). So a small positive pan moves the
// image of a static world point toward image -x.
//
// World frame (ours): origin on the pan axis, Z up, X the viewing direction at q = (0, 0),
// Y to the left. Pan q1 rotates about world -Z (a positive q1 turns the axis from +X toward -Y,
// i.e. to the right); tilt q2 then rotates about the pan-rotated Y axis (positive looks down).
// The camera frame is the optical one of decode::SensorGeometry (x right, y down, z forward).
#pragma once

#include <Eigen/Geometry>

namespace avs::geometry {

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

/// Joint angles (servo convention, see above).
struct HeadAngles {
  double pan_rad = 0;
  double tilt_rad = 0;
};

/// Rotation from the camera optical frame to the head frame (X forward, Y left, Z up).
Eigen::Matrix3d R_head_optical();

/// The head's links (frames.hpp): pan_link in the world, T(p_world_pan) Rz(-q1).
Eigen::Isometry3d T_world_pan(const HeadConfig& head, double q1_pan_rad);
/// tilt_link in pan_link: T(p_pan_tilt) Ry(q2).
Eigen::Isometry3d T_pan_tilt(const HeadConfig& head, double q2_tilt_rad);
/// camera_optical_frame in tilt_link (fixed): T(p_tilt_camera) R_head_optical.
Eigen::Isometry3d T_tilt_camera(const HeadConfig& head);

/// Pose of the camera optical frame (x right, y down, z forward) in the world:
/// T_world_pan * T_pan_tilt * T_tilt_camera =
/// T(p_world_pan) Rz(-q1) T(p_pan_tilt) Ry(q2) T(p_tilt_camera) R_head_optical.
Eigen::Isometry3d T_world_camera(const HeadConfig& head, double q1_pan_rad, double q2_tilt_rad);

/// Joint angles that point the optical axis at p_world, ignoring the camera offsets (exact
/// when p_tilt_camera_m is zero); handy for aiming the head at a target in tests and scenes.
HeadAngles look_at(const HeadConfig& head, const Eigen::Vector3d& p_world);

}  // namespace avs::geometry
