#include "avs/matching/features.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

namespace avs::matching {
namespace {

struct LocalFrame {
  Eigen::Vector3f centre;
  Eigen::Vector3f normal;  // e_0
  Eigen::Vector3f second;  // e_1
};

// Eqs. 17-18: centre and covariance of the neighbourhood; eigenvectors sorted ascending.
LocalFrame local_frame(const Points& points, const std::uint32_t* indices, std::size_t count) {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (std::size_t j = 0; j < count; ++j) centre += points[indices[j]];
  centre /= static_cast<float>(count);
  Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3f d = points[indices[j]] - centre;
    covariance.noalias() += d * d.transpose();
  }
  covariance /= static_cast<float>(count);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver(covariance);
  return {centre, solver.eigenvectors().col(0), solver.eigenvectors().col(1)};
}

}  // namespace

PointFeatures compute_features(const Points& points, const KdTree& tree,
                               const FeatureConfig& config, const NormalOrientation& orientation) {
  PointFeatures features;
  const std::size_t n = points.size();
  features.normals.assign(n, Eigen::Vector3f::Zero());
  features.curvature.assign(n, 0.0F);
  features.curvature_normalised.assign(n, 0.0F);
  features.neighbour_offsets.assign(n + 1, 0);
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto& p : points) centroid += p;
  if (n > 0) centroid /= static_cast<float>(n);

  std::vector<std::pair<std::uint32_t, float>> found;
  std::vector<std::uint32_t> indices;
  float k_max = 0.0F;
  for (std::size_t i = 0; i < n; ++i) {
    tree.radius_search(points[i], config.neighbourhood_radius_m, found);
    indices.clear();
    for (const auto& [index, squared] : found) indices.push_back(index);
    features.neighbours.insert(features.neighbours.end(), indices.begin(), indices.end());
    features.neighbour_offsets[i + 1] = static_cast<std::uint32_t>(features.neighbours.size());
    if (indices.size() < config.min_neighbours) continue;

    const LocalFrame frame = local_frame(points, indices.data(), indices.size());
    Eigen::Vector3f normal = frame.normal;
    // Orientation: the paper reverses e_0 when the angle between p_i and e_0 is below pi/2, i.e.
    // normals point toward the camera. The model uses its mesh normals instead.
    if (orientation.reference_normals != nullptr && !(*orientation.reference_normals)[i].isZero()) {
      if (normal.dot((*orientation.reference_normals)[i]) < 0.0F) normal = -normal;
    } else if (orientation.reference_normals != nullptr) {
      if (normal.dot(points[i] - centroid) < 0.0F) normal = -normal;
    } else if (normal.dot(points[i] - orientation.viewpoint) > 0.0F) {
      normal = -normal;
    }
    features.normals[i] = normal;

    // Eq. 19: k_i = 2 d_i / mu_i^2, d_i = |e_0 . (p_i - c_i)|, mu_i = mean |q_j - p_i|.
    const float d = std::abs(frame.normal.dot(points[i] - frame.centre));
    float mu = 0.0F;
    for (const auto index : indices) mu += (points[index] - points[i]).norm();
    mu /= static_cast<float>(indices.size());
    const float k = mu > 0.0F ? 2.0F * d / (mu * mu) : 0.0F;
    features.curvature[i] = k;
    k_max = std::max(k_max, k);
  }
  if (k_max > 0.0F) {
    for (std::size_t i = 0; i < n; ++i)
      features.curvature_normalised[i] = features.curvature[i] / k_max;
  }
  return features;
}

std::vector<Lrf> compute_lrfs(const Points& points, const PointFeatures& features,
                              const FeatureConfig& config) {
  std::vector<Lrf> lrfs;
  const int bins = std::max(config.vote_bins, 8);
  std::vector<float> votes(static_cast<std::size_t>(bins));
  std::vector<float> smoothed(static_cast<std::size_t>(bins));
  const float bin_width = 2.0F * std::numbers::pi_v<float> / static_cast<float>(bins);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& normal = features.normals[i];
    if (normal.isZero() || features.curvature_normalised[i] <= config.curvature_threshold) continue;

    // 1. Tangent basis (u, v) of the feature point.
    const Eigen::Vector3f u = normal.unitOrthogonal();
    const Eigen::Vector3f v = normal.cross(u);

    // 2. Vote: each neighbour's normal projected on the tangent plane, weighted by its length.
    std::fill(votes.begin(), votes.end(), 0.0F);
    for (std::uint32_t k = features.neighbour_offsets[i]; k < features.neighbour_offsets[i + 1];
         ++k) {
      const Eigen::Vector3f& other = features.normals[features.neighbours[k]];
      if (other.isZero()) continue;
      const Eigen::Vector3f tangent = other - other.dot(normal) * normal;
      const float weight = tangent.norm();
      if (weight < 1e-3F) continue;
      float angle = std::atan2(tangent.dot(v), tangent.dot(u));
      if (angle < 0.0F) angle += 2.0F * std::numbers::pi_v<float>;
      const int bin = std::min(bins - 1, static_cast<int>(angle / bin_width));
      votes[static_cast<std::size_t>(bin)] += weight;
    }
    for (int b = 0; b < bins; ++b) {
      const auto at = [&](int index) {
        return votes[static_cast<std::size_t>((index + bins) % bins)];
      };
      smoothed[static_cast<std::size_t>(b)] = 0.25F * at(b - 1) + 0.5F * at(b) + 0.25F * at(b + 1);
    }

    // 3. Peaks: the highest bin, and a second local maximum far from it if nearly as high.
    const auto first =
        static_cast<int>(std::max_element(smoothed.begin(), smoothed.end()) - smoothed.begin());
    const float first_height = smoothed[static_cast<std::size_t>(first)];
    if (first_height <= 0.0F) continue;
    int second = -1;
    for (int b = 0; b < bins; ++b) {
      const int distance = std::min((b - first + bins) % bins, (first - b + bins) % bins);
      if (distance < bins / 6) continue;
      const float h = smoothed[static_cast<std::size_t>(b)];
      const bool local_max = h >= smoothed[static_cast<std::size_t>((b + 1) % bins)] &&
                             h >= smoothed[static_cast<std::size_t>((b + bins - 1) % bins)];
      if (local_max && h >= config.second_peak_ratio * first_height &&
          (second < 0 || h > smoothed[static_cast<std::size_t>(second)])) {
        second = b;
      }
    }
    for (const int peak : {first, second}) {
      if (peak < 0) continue;
      const float angle = (static_cast<float>(peak) + 0.5F) * bin_width;
      Eigen::Vector3f axis = std::cos(angle) * u + std::sin(angle) * v;
      // Refine: mean of the projected normals that voted within one bin of the peak.
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (std::uint32_t k = features.neighbour_offsets[i]; k < features.neighbour_offsets[i + 1];
           ++k) {
        const Eigen::Vector3f& other = features.normals[features.neighbours[k]];
        const Eigen::Vector3f tangent = other - other.dot(normal) * normal;
        const float length = tangent.norm();
        if (length < 1e-3F) continue;
        if (tangent.dot(axis) > length * std::cos(1.5F * bin_width)) sum += tangent;
      }
      if (sum.norm() > 1e-6F) axis = (sum - sum.dot(normal) * normal).normalized();
      Lrf lrf;
      lrf.axes.col(0) = normal;
      lrf.axes.col(1) = axis;
      lrf.axes.col(2) = normal.cross(axis);
      lrf.origin_m = points[i];
      lrf.point = static_cast<std::uint32_t>(i);
      lrf.curvature = features.curvature_normalised[i];
      lrfs.push_back(lrf);
    }
  }
  return lrfs;
}

Points estimate_normals(const Points& points, std::size_t neighbours) {
  Points normals(points.size(), Eigen::Vector3f::UnitZ());
  if (points.size() < 3) return normals;
  const KdTree tree(points);
  const std::size_t k = std::min(neighbours, points.size());
  std::vector<std::uint32_t> indices(k);
  std::vector<float> squared(k);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t found = tree.knn(points[i], k, indices.data(), squared.data());
    if (found >= 3) normals[i] = local_frame(points, indices.data(), found).normal;
  }
  return normals;
}

}  // namespace avs::matching
