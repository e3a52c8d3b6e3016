#include "avs/matching/model_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "avs/matching/kd_tree.hpp"
#include "avs/matching/voxel_grid.hpp"

namespace avs::matching {

SurfaceSamples sample_surface(const geometry::Mesh& mesh, std::size_t count, std::uint32_t seed) {
  // 1. Cumulative triangle areas for area-weighted triangle choice.
  std::vector<double> cumulative_area;
  cumulative_area.reserve(mesh.triangles.size());
  double total = 0.0;
  const auto vertex_count = static_cast<int>(mesh.vertices.size());
  for (const auto& triangle : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (triangle[k] < 0 || triangle[k] >= vertex_count) {
        throw std::invalid_argument("sample_surface: triangle index " +
                                    std::to_string(triangle[k]) + " out of range (" +
                                    std::to_string(vertex_count) + " vertices)");
      }
    }
    const Eigen::Vector3f& a = mesh.vertices[static_cast<std::size_t>(triangle[0])];
    const Eigen::Vector3f& b = mesh.vertices[static_cast<std::size_t>(triangle[1])];
    const Eigen::Vector3f& c = mesh.vertices[static_cast<std::size_t>(triangle[2])];
    total += 0.5 * static_cast<double>((b - a).cross(c - a).norm());
    cumulative_area.push_back(total);
  }
  if (!(total > 0.0)) throw std::invalid_argument("sample_surface: mesh has no surface area");

  // 2. Uniform point in the chosen triangle (square-root barycentric trick).
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> area_pick(0.0, total);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  SurfaceSamples samples;
  samples.points_m.reserve(count);
  samples.normals.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const auto it =
        std::upper_bound(cumulative_area.begin(), cumulative_area.end(), area_pick(rng));
    const auto& triangle = mesh.triangles[static_cast<std::size_t>(std::min<std::ptrdiff_t>(
        it - cumulative_area.begin(), static_cast<std::ptrdiff_t>(cumulative_area.size()) - 1))];
    const Eigen::Vector3f& a = mesh.vertices[static_cast<std::size_t>(triangle[0])];
    const Eigen::Vector3f& b = mesh.vertices[static_cast<std::size_t>(triangle[1])];
    const Eigen::Vector3f& c = mesh.vertices[static_cast<std::size_t>(triangle[2])];
    const float s = std::sqrt(unit(rng));
    const float t = unit(rng);
    samples.points_m.push_back((1.0F - s) * a + s * (1.0F - t) * b + s * t * c);
    const Eigen::Vector3f normal = (b - a).cross(c - a);
    const float norm = normal.norm();
    samples.normals.push_back(norm > 0.0F ? Eigen::Vector3f(normal / norm)
                                          : Eigen::Vector3f::Zero());
  }
  return samples;
}

ModelCloud make_model_cloud(const geometry::Mesh& mesh, const ModelCloudConfig& config) {
  if (config.target_points == 0 || config.surface_samples < config.target_points) {
    throw std::invalid_argument("make_model_cloud: need 0 < target_points (" +
                                std::to_string(config.target_points) + ") <= surface_samples (" +
                                std::to_string(config.surface_samples) + ")");
  }
  // 0. A size the float clouds, voxel keys and distance grid can work with. Far beyond it (a
  //    mesh scaled by 1e12-1e30) areas overflow and voxel keys saturate, and the failure named
  //    a symptom ("no surface area", "needs 3 points"); say the size instead (issue 20).
  Eigen::AlignedBox3d box_m;
  for (const auto& v : mesh.vertices) {
    if (!v.allFinite()) throw std::invalid_argument("make_model_cloud: a vertex is not finite");
    box_m.extend(v.cast<double>());
  }
  const double size_m = box_m.isEmpty() ? 0.0 : box_m.diagonal().norm();
  if (size_m > kMaxModelSizeM) {
    throw std::invalid_argument("make_model_cloud: the mesh is " + std::to_string(size_m) +
                                " m across, above the " + std::to_string(kMaxModelSizeM) +
                                " m a model may be (is it in metres?)");
  }
  // 1. Dense uniform samples.
  const SurfaceSamples samples = sample_surface(mesh, config.surface_samples, config.seed);

  // 2. Bisection on log(voxel size): the voxel count falls as the voxel grows. The count is a
  //    step function of the size and of the grid's offset, so the neighbourhood of the bisection
  //    result is then searched over a few sizes and grid offsets for the closest count.
  Eigen::AlignedBox3f box;
  for (const auto& p : samples.points_m) box.extend(p);
  // The bracket scales with the model, so a tiny one (a mesh in the wrong unit, warned about by
  // the matching component) still gets voxels smaller than itself.
  double small = std::min(1e-5, 1e-4 * size_m);
  double large = std::max(10.0 * small, static_cast<double>(box.diagonal().maxCoeff()));
  VoxelGridScratch scratch;
  Points shifted;
  Points points;
  Points normals;
  ModelCloud best;
  std::size_t best_error = std::numeric_limits<std::size_t>::max();
  auto try_size = [&](double size, float offset_fraction) {
    const Eigen::Vector3f shift =
        Eigen::Vector3f::Constant(static_cast<float>(size) * offset_fraction);
    shifted.resize(samples.points_m.size());
    for (std::size_t i = 0; i < shifted.size(); ++i) shifted[i] = samples.points_m[i] + shift;
    voxel_downsample(shifted, static_cast<float>(size), points, scratch, &samples.normals,
                     &normals);
    const std::size_t error = points.size() > config.target_points
                                  ? points.size() - config.target_points
                                  : config.target_points - points.size();
    if (error < best_error) {
      best_error = error;
      best.points_m = points;
      for (auto& p : best.points_m) p -= shift;
      best.normals = normals;
      best.voxel_size_m = static_cast<float>(size);
    }
    return points.size();
  };
  for (int step = 0; step < config.max_search_steps && best_error > 0; ++step) {
    const double size = std::sqrt(small * large);
    (try_size(size, 0.0F) > config.target_points ? small : large) = size;
  }
  const double centre = best.voxel_size_m;
  for (int k = -4; k <= 4 && best_error > 0; ++k) {
    for (int offset = 1; offset < 8 && best_error > 0; ++offset) {
      try_size(centre * (1.0 + 0.01 * k), static_cast<float>(offset) / 8.0F);
    }
  }

  const std::size_t dense = std::min(config.verification_points, samples.points_m.size());
  best.dense_points_m.assign(samples.points_m.begin(),
                             samples.points_m.begin() + static_cast<std::ptrdiff_t>(dense));
  best.dense_normals.assign(samples.normals.begin(),
                            samples.normals.begin() + static_cast<std::ptrdiff_t>(dense));

  // 3. Mean nearest-neighbour spacing: the natural length scale for neighbourhoods.
  const KdTree tree(best.points_m);
  double spacing = 0.0;
  for (const auto& p : best.points_m) {
    std::uint32_t indices[2];
    float squared[2];
    if (tree.knn(p, 2, indices, squared) == 2)
      spacing += std::sqrt(static_cast<double>(squared[1]));
  }
  best.mean_spacing_m = static_cast<float>(spacing / static_cast<double>(best.points_m.size()));
  return best;
}

}  // namespace avs::matching
