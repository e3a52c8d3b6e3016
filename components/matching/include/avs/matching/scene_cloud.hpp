// Scene point cloud (S-PCD) from a depth image (paper section 6.3): stride sampling of the
// target's pixels by Eq. 27, voxel down-sampling with side r (centroid per voxel), and removal of
// points whose mean distance to their nearest neighbours exceeds a threshold.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "avs/matching/cloud.hpp"
#include "avs/matching/neighbour_grid.hpp"
#include "avs/matching/voxel_grid.hpp"

namespace avs::matching {

struct SceneCloudConfig {
  std::size_t target_points = 250;  ///< i_number of Eq. 27 (paper: 250 ken, 350 cube, 300 cylinder)
  float voxel_size_m = 0.00757F;    ///< r (paper: 7.57 mm)
  /// Neighbours averaged by the outlier test (paper: 20); at most a twelfth of the cloud.
  std::size_t outlier_neighbours = 20;
  float outlier_mean_distance_m = 0.03F;  ///< drop a point whose mean neighbour distance is larger
  float min_depth_m = 0.05F;              ///< depths outside [min, max] are treated as invalid
  float max_depth_m = 10.0F;
};

/// Builds S-PCDs frame after frame, reusing its buffers.
class SceneCloudBuilder {
 public:
  explicit SceneCloudBuilder(SceneCloudConfig config = {}) : config_(config) {}

  /// Returns the S-PCD in the camera frame (valid until the next call).
  const Points& build(const DepthView& depth, const MaskView& mask,
                      const geometry::CameraModel& camera);

  /// Number of valid target pixels M of the last frame (Eq. 27).
  [[nodiscard]] std::size_t valid_pixels() const { return valid_pixels_; }
  /// Points after stride sampling, before voxel down-sampling.
  [[nodiscard]] std::size_t sampled_points() const { return sampled_.size(); }
  [[nodiscard]] const SceneCloudConfig& config() const { return config_; }
  /// The depth window (live parameters); the scratch buffers are kept.
  void set_depth_window(float min_depth_m, float max_depth_m) {
    config_.min_depth_m = min_depth_m;
    config_.max_depth_m = max_depth_m;
  }

 private:
  SceneCloudConfig config_;
  std::size_t valid_pixels_ = 0;
  std::vector<std::uint32_t> row_valid_;  ///< valid pixels per image row of the last frame
  Points sampled_;
  Points voxels_;
  Points result_;
  VoxelGridScratch scratch_;
  NeighbourGrid knn_grid_;  ///< the outlier test's neighbour search, rebuilt per frame in place
  std::vector<std::uint32_t> knn_indices_;
  std::vector<float> knn_squared_;
};

/// Stride ratio C_p of Eq. 27 for M valid pixels and a target of i_number points.
[[nodiscard]] double stride_ratio(std::size_t valid_pixels, std::size_t target_points);

/// Removes points whose mean distance to their k nearest neighbours exceeds the threshold
/// (k = min(neighbours, max(4, size / 12))).
[[nodiscard]] Points remove_outliers(const Points& points, std::size_t neighbours,
                                     float mean_distance_threshold_m);

}  // namespace avs::matching
