// Pan/tilt head for the simulator: the kinematics live in avs/geometry/head_kinematics.hpp
// (servo sign convention: positive pan turns the optical axis toward image +x, positive tilt
// toward image +y); this header keeps the sim names and adds HeadState (angles and rates).
#pragma once

#include <Eigen/Geometry>

#include "avs/geometry/head_kinematics.hpp"

namespace avs::sim {

using geometry::HeadAngles;
using geometry::HeadConfig;
using geometry::look_at;
using geometry::R_head_optical;
using geometry::T_world_camera;

/// Joint angles and rates at one instant (servo convention).
struct HeadState {
  double pan_rad = 0;
  double tilt_rad = 0;
  double pan_rate_rad_s = 0;
  double tilt_rate_rad_s = 0;
};

/// The head standing still at angles q (e.g. at_rest(look_at(config.head, p_world)), with
/// geometry::look_at found by argument-dependent lookup).
inline HeadState at_rest(const geometry::HeadAngles& q) {
  return HeadState{q.pan_rad, q.tilt_rad, 0, 0};
}

}  // namespace avs::sim
