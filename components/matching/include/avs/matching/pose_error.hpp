// Pose error between an estimate and the ground truth, modulo the object's symmetry.
#pragma once

#include <string>

#include "avs/matching/cloud.hpp"

namespace avs::matching {

enum class Symmetry {
  none,        ///< e.g. the ken
  cube,        ///< 24 proper rotations of a cube centred on the origin
  cylinder_z,  ///< any rotation about z, and the flip about a perpendicular axis
};

[[nodiscard]] Symmetry parse_symmetry(const std::string& name);  ///< "none", "cube", "cylinder_z"

struct PoseError {
  float rotation_deg = 0.0F;
  float translation_m = 0.0F;
};

/// Smallest rotation angle between T_estimate and T_truth over the symmetry group, and the
/// distance between their origins (the symmetry centre is the model origin).
[[nodiscard]] PoseError pose_error(const Eigen::Isometry3f& T_camera_model_estimate,
                                   const Eigen::Isometry3f& T_camera_model_truth,
                                   Symmetry symmetry);

}  // namespace avs::matching
