// Planar patches for the plane hypotheses of the initial alignment. Our addition beyond the paper
// (section 6.1 proposes poses from LRFs at curved feature points only); see features.hpp.
#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "avs/matching/features.hpp"

namespace avs::matching {
namespace {

struct Fit {
  Eigen::Vector3f normal;
  Eigen::Vector3f centroid;
  float thickness;   // standard deviation along the normal
  float min_extent;  // smaller in-plane standard deviation
};

// Centre and covariance of the members (as Eqs. 17-18 for a neighbourhood); normal = eigenvector
// of the smallest eigenvalue, turned like `orientation`.
Fit fit_plane(const Points& points, const std::vector<std::uint32_t>& members,
              const Eigen::Vector3f& orientation) {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto m : members) centroid += points[m];
  centroid /= static_cast<float>(members.size());
  Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
  for (const auto m : members) {
    const Eigen::Vector3f d = points[m] - centroid;
    covariance.noalias() += d * d.transpose();
  }
  covariance /= static_cast<float>(members.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver(covariance);
  Eigen::Vector3f normal = solver.eigenvectors().col(0);
  if (normal.dot(orientation) < 0.0F) normal = -normal;
  return {normal, centroid, std::sqrt(std::max(0.0F, solver.eigenvalues()(0))),
          std::sqrt(std::max(0.0F, solver.eigenvalues()(1)))};
}

}  // namespace

std::vector<PlanarPatch> find_planar_patches(const Points& points, const Points& normals,
                                             const PlaneConfig& config, float spacing_m) {
  std::vector<PlanarPatch> patches;
  const std::size_t n = std::min(points.size(), normals.size());
  if (n == 0 || !(spacing_m > 0.0F)) return patches;
  const float cos_tolerance = std::cos(config.normal_tolerance_rad);
  const float offset = config.offset_tolerance * spacing_m;
  const auto min_points =
      std::max(config.min_points,
               static_cast<std::size_t>(std::ceil(config.min_fraction * static_cast<float>(n))));
  std::vector<bool> taken(n, false);
  for (std::size_t i = 0; i < n; ++i) taken[i] = normals[i].isZero();
  const std::size_t stride =
      std::max<std::size_t>(1, n / std::max<std::size_t>(1, config.max_seeds));
  std::vector<std::uint32_t> members;
  const auto collect = [&](const Eigen::Vector3f& normal, const Eigen::Vector3f& on_plane) {
    members.clear();
    for (std::size_t j = 0; j < n; ++j) {
      if (taken[j] || normals[j].dot(normal) < cos_tolerance) continue;
      if (std::abs(normal.dot(points[j] - on_plane)) > offset) continue;
      members.push_back(static_cast<std::uint32_t>(j));
    }
  };
  // Each round: the seed whose plane gathers most free points, refitted; at most max_patches
  // accepted, and a few rounds more for rejected (thin) ones.
  for (std::size_t round = 0; patches.size() < config.max_patches && round < 2 * config.max_patches;
       ++round) {
    std::size_t best_seed = n;
    std::size_t best_count = 0;
    for (std::size_t i = 0; i < n; i += stride) {
      if (taken[i]) continue;
      collect(normals[i].normalized(), points[i]);
      if (members.size() > best_count) {
        best_count = members.size();
        best_seed = i;
      }
    }
    if (best_seed == n || best_count < min_points) break;
    collect(normals[best_seed].normalized(), points[best_seed]);
    Fit fit = fit_plane(points, members, normals[best_seed]);
    collect(fit.normal, fit.centroid);  // refitted plane: members again, and the final fit
    if (members.size() < 3) break;
    fit = fit_plane(points, members, fit.normal);
    for (const auto m : members) taken[m] = true;
    if (members.size() < min_points || fit.min_extent < config.min_extent * spacing_m ||
        fit.thickness > offset) {
      continue;  // a strip of a curved surface, or not flat: its points are spent
    }
    patches.push_back({fit.normal, fit.centroid, members.size()});
  }
  return patches;
}

}  // namespace avs::matching
