// Pan/tilt head kinematics (see head.hpp).
#include "avs/sim/head.hpp"

#include <cmath>

namespace avs::sim {

Eigen::Matrix3d R_head_optical() {
  Eigen::Matrix3d R;
  // Columns: optical x (right) = -Y, optical y (down) = -Z, optical z (forward) = +X.
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return R;
}

Eigen::Isometry3d T_world_camera(const HeadConfig& head, double pan_rad, double tilt_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(head.p_world_pan_m);
  T.rotate(Eigen::AngleAxisd(pan_rad, Eigen::Vector3d::UnitZ()));
  T.translate(head.p_pan_tilt_m);
  T.rotate(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()));
  T.translate(head.p_tilt_camera_m);
  T.rotate(R_head_optical());
  return T;
}

HeadState look_at(const HeadConfig& head, const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d d = p_world - head.p_world_pan_m - head.p_pan_tilt_m;
  HeadState state;
  state.pan_rad = std::atan2(d.y(), d.x());
  state.tilt_rad = std::atan2(-d.z(), std::hypot(d.x(), d.y()));  // positive looks down
  return state;
}

}  // namespace avs::sim
