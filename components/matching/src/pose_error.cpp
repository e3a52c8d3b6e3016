#include "avs/matching/pose_error.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace avs::matching {
namespace {

float angle_deg(const Eigen::Matrix3f& r) {
  const float c = std::clamp((r.trace() - 1.0F) * 0.5F, -1.0F, 1.0F);
  return std::acos(c) * 180.0F / std::numbers::pi_v<float>;
}

std::vector<Eigen::Matrix3f> cube_group() {
  std::vector<Eigen::Matrix3f> group;
  const std::array<std::array<int, 3>, 6> permutations{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& perm : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3f m = Eigen::Matrix3f::Zero();
      for (int row = 0; row < 3; ++row) {
        m(row, perm[static_cast<std::size_t>(row)]) = ((signs >> row) & 1) != 0 ? -1.0F : 1.0F;
      }
      if (m.determinant() > 0.0F) group.push_back(m);
    }
  }
  return group;
}

}  // namespace

Symmetry parse_symmetry(const std::string& name) {
  if (name == "none") return Symmetry::none;
  if (name == "cube") return Symmetry::cube;
  if (name == "cylinder_z") return Symmetry::cylinder_z;
  throw std::invalid_argument("unknown symmetry '" + name + "' (expected none, cube, cylinder_z)");
}

PoseError pose_error(const Eigen::Isometry3f& T_camera_model_estimate,
                     const Eigen::Isometry3f& T_camera_model_truth, Symmetry symmetry) {
  PoseError error;
  error.translation_m =
      (T_camera_model_estimate.translation() - T_camera_model_truth.translation()).norm();
  const Eigen::Matrix3f r_est = T_camera_model_estimate.linear();
  const Eigen::Matrix3f r_true = T_camera_model_truth.linear();
  switch (symmetry) {
    case Symmetry::none:
      error.rotation_deg = angle_deg(r_true.transpose() * r_est);
      break;
    case Symmetry::cube: {
      static const std::vector<Eigen::Matrix3f> group = cube_group();
      error.rotation_deg = 180.0F;
      for (const auto& g : group) {
        error.rotation_deg =
            std::min(error.rotation_deg, angle_deg(r_true.transpose() * r_est * g));
      }
      break;
    }
    case Symmetry::cylinder_z: {
      const float c = std::abs(r_est.col(2).dot(r_true.col(2)));
      error.rotation_deg = std::acos(std::min(c, 1.0F)) * 180.0F / std::numbers::pi_v<float>;
      break;
    }
  }
  return error;
}

}  // namespace avs::matching
