#include "avs/matching/scene_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "avs/matching/neighbour_grid.hpp"

namespace avs::matching {
namespace {

bool usable(float z, const SceneCloudConfig& config) {
  return std::isfinite(z) && z >= config.min_depth_m && z <= config.max_depth_m;
}

void remove_outliers_into(const Points& in, std::size_t neighbours, float threshold_m, Points& out,
                          NeighbourGrid& grid, std::vector<std::uint32_t>& indices,
                          std::vector<float>& squared) {
  out.clear();
  if (in.size() <= 1 || neighbours == 0) {
    out = in;
    return;
  }
  // At most a twelfth of the cloud: in a small cloud (the ken seen edge-on, ~65 points after the
  // voxel step) 20 neighbours reach across the object and a thin part (its spike) would be taken
  // for outliers. Clouds of 240 points or more use `neighbours` as given.
  neighbours = std::min(neighbours, std::max<std::size_t>(4, in.size() / 12));
  grid.rebuild(in);  // small (a few hundred points); no allocation once the buffers have grown
  indices.resize(neighbours + 1);
  squared.resize(neighbours + 1);
  for (const auto& p : in) {
    const std::size_t found = grid.knn(p, neighbours + 1, indices.data(), squared.data());
    double sum = 0.0;
    for (std::size_t k = 1; k < found; ++k) sum += std::sqrt(static_cast<double>(squared[k]));
    const double mean = found > 1 ? sum / static_cast<double>(found - 1) : 0.0;
    if (mean <= static_cast<double>(threshold_m)) out.push_back(p);
  }
}

}  // namespace

double stride_ratio(std::size_t valid_pixels, std::size_t target_points) {
  // Eq. 27: C_p = M / i_number if M > i_number, else 1.
  if (target_points == 0 || valid_pixels <= target_points) return 1.0;
  return static_cast<double>(valid_pixels) / static_cast<double>(target_points);
}

const Points& SceneCloudBuilder::build(const DepthView& depth, const MaskView& mask,
                                       const geometry::CameraModel& camera) {
  if (depth.depth_m == nullptr || depth.width_px <= 0 || depth.height_px <= 0) {
    throw std::invalid_argument("SceneCloudBuilder::build: empty depth image");
  }
  if (const std::string problem = camera.problem(); !problem.empty()) {
    throw std::invalid_argument("SceneCloudBuilder::build: camera model: " + problem);
  }
  const int stride = depth.stride_px > 0 ? depth.stride_px : depth.width_px;
  const int mask_stride = mask.stride_px > 0 ? mask.stride_px : depth.width_px;
  auto valid = [&](int u, int v) {
    if (mask.mask != nullptr &&
        mask.mask[static_cast<std::size_t>(v) * static_cast<std::size_t>(mask_stride) +
                  static_cast<std::size_t>(u)] == 0) {
      return false;
    }
    return usable(depth.depth_m[static_cast<std::size_t>(v) * static_cast<std::size_t>(stride) +
                                static_cast<std::size_t>(u)],
                  config_);
  };

  // 1. Count the valid target pixels M, per row. Branch-free so that the compiler vectorises
  // it: usable() as one range test (NaN fails both comparisons; the bounds clamped to finite
  // floats exclude the infinities). The two passes over the whole image were a quarter of the
  // real-time pipeline's CPU time (docs/realtime.md).
  const float lowest = std::max(config_.min_depth_m, std::numeric_limits<float>::lowest());
  const float highest = std::min(config_.max_depth_m, std::numeric_limits<float>::max());
  row_valid_.resize(static_cast<std::size_t>(depth.height_px));
  valid_pixels_ = 0;
  for (int v = 0; v < depth.height_px; ++v) {
    const float* z = depth.depth_m + static_cast<std::size_t>(v) * static_cast<std::size_t>(stride);
    std::uint32_t count = 0;
    if (mask.mask == nullptr) {
      for (int u = 0; u < depth.width_px; ++u) count += (z[u] >= lowest) & (z[u] <= highest);
    } else {
      const std::uint8_t* m =
          mask.mask + static_cast<std::size_t>(v) * static_cast<std::size_t>(mask_stride);
      for (int u = 0; u < depth.width_px; ++u) {
        count += (m[u] != 0) & (z[u] >= lowest) & (z[u] <= highest);
      }
    }
    row_valid_[static_cast<std::size_t>(v)] = count;
    valid_pixels_ += count;
  }

  // 2. Keep the (i * C_p)-th valid pixel, i = 1, 2, ... (Eq. 27), back-projected to 3-D along
  // the pixel's ray (the pinhole in float, as before distortion was supported).
  const bool distorted = camera.has_distortion();
  const auto fx = static_cast<float>(camera.fx_px), fy = static_cast<float>(camera.fy_px);
  const auto cx = static_cast<float>(camera.cx_px), cy = static_cast<float>(camera.cy_px);
  const double ratio = stride_ratio(valid_pixels_, config_.target_points);
  sampled_.clear();
  std::size_t index = 0;
  double next = ratio - 1.0;  // 0-based index of the next pixel to keep
  for (int v = 0; v < depth.height_px; ++v) {
    // A row whose valid pixels all come before the next one to keep is passed whole.
    const std::uint32_t in_row = row_valid_[static_cast<std::size_t>(v)];
    if (in_row == 0 || static_cast<double>(index + in_row - 1) < next) {
      index += in_row;
      continue;
    }
    for (int u = 0; u < depth.width_px; ++u) {
      if (!valid(u, v)) continue;
      if (static_cast<double>(index) >= next) {
        const float z =
            depth.depth_m[static_cast<std::size_t>(v) * static_cast<std::size_t>(stride) +
                          static_cast<std::size_t>(u)];
        if (distorted) {
          const Eigen::Vector3d ray = camera.ray(u, v);  // distortion removed
          sampled_.emplace_back(static_cast<float>(ray.x()) * z, static_cast<float>(ray.y()) * z,
                                z);
        } else {
          sampled_.emplace_back((static_cast<float>(u) - cx) * z / fx,
                                (static_cast<float>(v) - cy) * z / fy, z);
        }
        next += ratio;
      }
      ++index;
    }
  }

  // 3. Voxel down-sampling with side r, centroid per voxel.
  if (config_.voxel_size_m > 0.0F) {
    voxel_downsample(sampled_, config_.voxel_size_m, voxels_, scratch_);
  } else {
    voxels_ = sampled_;
  }

  // 4. Outliers: mean distance to the k nearest neighbours above the threshold.
  remove_outliers_into(voxels_, config_.outlier_neighbours, config_.outlier_mean_distance_m,
                       result_, knn_grid_, knn_indices_, knn_squared_);
  return result_;
}

Points remove_outliers(const Points& points, std::size_t neighbours,
                       float mean_distance_threshold_m) {
  Points out;
  NeighbourGrid grid;
  std::vector<std::uint32_t> indices;
  std::vector<float> squared;
  remove_outliers_into(points, neighbours, mean_distance_threshold_m, out, grid, indices, squared);
  return out;
}

}  // namespace avs::matching
