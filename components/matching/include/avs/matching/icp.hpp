// Iterative Closest Point (paper section 6.2, Eqs. 21-26): closest model point through a kd-tree
// built once on the model, point-to-point SVD with reflection correction, coarse-to-fine
// [n1, n2, n3] iterations on 1/4, 1/2 and all scene points, fixed count. Point-to-plane optional.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "avs/matching/cloud.hpp"
#include "avs/matching/kd_tree.hpp"

namespace avs::matching {

enum class IcpMetric { point_to_point, point_to_plane };

struct IcpConfig {
  std::array<int, 3> iterations{0, 0, 1};  ///< [n1, n2, n3] on 1/4, 1/2, all scene points
  IcpMetric metric = IcpMetric::point_to_point;
  float max_correspondence_distance_m = 0.03F;  ///< farther pairs are not used
  float inlier_distance_m = 0.0F;  ///< residual below this is an inlier; 0 = model's mean spacing
  std::size_t normal_neighbours = 10;  ///< for model normals (point-to-plane)
  /// Trimmed ICP (issue 19, clutter): each iteration leaves out the pairs farther apart than
  /// trim_factor x the median pair distance (and never below trim_floor_m), so a surface beside
  /// the target (a hand holding it) does not pull the pose while the pairs of the target, whose
  /// distances are the sensor's noise, all stay. 0 = off (every pair within
  /// max_correspondence_distance_m is used).
  float trim_factor = 0.0F;
  float trim_floor_m = 0.003F;
};

struct IcpResult {
  Eigen::Isometry3f T_camera_model = Eigen::Isometry3f::Identity();
  float rmse_m = 0.0F;      ///< RMS residual of the last iteration's pairs, after its update
  std::size_t inliers = 0;  ///< pairs with residual below inlier_distance_m
  std::size_t correspondences = 0;  ///< pairs used in the last iteration
  std::size_t scene_points = 0;
  int iterations = 0;
  bool valid = false;  ///< false when fewer than 3 pairs were found
  [[nodiscard]] float inlier_ratio() const {
    return scene_points > 0 ? static_cast<float>(inliers) / static_cast<float>(scene_points) : 0.0F;
  }
};

/// One model (M-PCD) and its kd-tree; align() reuses internal buffers (no allocation once the
/// buffers have grown to the largest scene seen). Not thread-safe: one Icp per thread.
class Icp {
 public:
  /// model_normals: needed for point-to-plane; estimated from the model when empty.
  explicit Icp(Points model_points_m, IcpConfig config = {}, Points model_normals = {});

  /// Runs config().iterations from the guess.
  IcpResult align(const Points& p_camera, const Eigen::Isometry3f& T_camera_model_guess);
  /// Runs the given [n1, n2, n3]; [0, 0, 0] only evaluates the residual of the guess.
  IcpResult align(const Points& p_camera, const Eigen::Isometry3f& T_camera_model_guess,
                  const std::array<int, 3>& iterations);

  /// Reserves buffers for scenes of up to `points` points.
  void reserve(std::size_t points);

  [[nodiscard]] const KdTree& tree() const { return tree_; }
  [[nodiscard]] const Points& model_points() const { return tree_.points(); }
  [[nodiscard]] const IcpConfig& config() const { return config_; }
  /// Mean distance from a model point to its nearest other model point.
  [[nodiscard]] float model_spacing_m() const { return model_spacing_m_; }

 private:
  // One iteration on every `step`-th scene point; updates T_model_camera. Returns pair count.
  std::size_t iterate(const Points& p_camera, std::size_t step, Eigen::Isometry3f& T_model_camera);
  // Pairs every `step`-th scene point with its closest model point (then trims).
  void pair_up(const Points& p_camera, std::size_t step, const Eigen::Isometry3f& T_model_camera);
  // Trimming (IcpConfig::trim_factor): drops the far pairs of the current set.
  void trim();
  void evaluate(const Eigen::Isometry3f& T_model_camera, IcpResult& result) const;

  KdTree tree_;
  Points normals_;
  IcpConfig config_;
  float model_spacing_m_ = 0.0F;
  Points source_;                      // scene points in the model frame, paired ...
  std::vector<std::uint32_t> target_;  // ... with these model points
  std::vector<float> squared_;         // ... at these squared distances (trimming)
  std::vector<float> median_scratch_;  // nth_element's working copy of squared_
  std::size_t pairs_ = 0;
};

/// Optimal rigid transform y ~ R p + t between paired points (Eqs. 22-26), with the reflection
/// correction of Eq. 25.
[[nodiscard]] Eigen::Isometry3f fit_rigid(const Points& p, const Points& y, std::size_t count);

}  // namespace avs::matching
