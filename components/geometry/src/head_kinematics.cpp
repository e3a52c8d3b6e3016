// Pan/tilt head kinematics (see head_kinematics.hpp for the sign convention).
#include "avs/geometry/head_kinematics.hpp"

#include <cmath>

namespace avs::geometry {

Eigen::Matrix3d R_head_optical() {
  Eigen::Matrix3d R;
  // Columns: optical x (right) = -Y, optical y (down) = -Z, optical z (forward) = +X.
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return R;
}

Eigen::Isometry3d T_world_pan(const HeadConfig& head, double q1_pan_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(head.p_world_pan_m);
  // Rotation about -Z: positive pan turns the optical axis (+X) toward -Y, image +x.
  T.rotate(Eigen::AngleAxisd(q1_pan_rad, -Eigen::Vector3d::UnitZ()));
  return T;
}

Eigen::Isometry3d T_pan_tilt(const HeadConfig& head, double q2_tilt_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(head.p_pan_tilt_m);
  // Rotation about +Y: positive tilt turns +X toward -Z (down), image +y.
  T.rotate(Eigen::AngleAxisd(q2_tilt_rad, Eigen::Vector3d::UnitY()));
  return T;
}

Eigen::Isometry3d T_tilt_camera(const HeadConfig& head) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(head.p_tilt_camera_m);
  T.rotate(R_head_optical());
  return T;
}

Eigen::Isometry3d T_world_camera(const HeadConfig& head, double q1_pan_rad, double q2_tilt_rad) {
  return T_world_pan(head, q1_pan_rad) * T_pan_tilt(head, q2_tilt_rad) * T_tilt_camera(head);
}

HeadAngles look_at(const HeadConfig& head, const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d d = p_world - head.p_world_pan_m - head.p_pan_tilt_m;
  HeadAngles q;
  q.pan_rad = std::atan2(-d.y(), d.x());                      // positive turns right
  q.tilt_rad = std::atan2(-d.z(), std::hypot(d.x(), d.y()));  // positive looks down
  return q;
}

}  // namespace avs::geometry
