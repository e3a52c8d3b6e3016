#include "avs/matching/icp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "avs/matching/features.hpp"

namespace avs::matching {
namespace {

// Eqs. 22-26 on paired points given through accessors.
template <class Source, class Target>
Eigen::Isometry3f fit_pairs(std::size_t count, Source source, Target target) {
  // Eq. 23: centroids.
  Eigen::Vector3f mean_p = Eigen::Vector3f::Zero();
  Eigen::Vector3f mean_y = Eigen::Vector3f::Zero();
  for (std::size_t i = 0; i < count; ++i) {
    mean_p += source(i);
    mean_y += target(i);
  }
  const float inverse = 1.0F / static_cast<float>(count);
  mean_p *= inverse;
  mean_y *= inverse;
  // Eq. 22: Sigma_py = 1/N sum (p - mu_p)(y - mu_y)^T.
  Eigen::Matrix3f sigma = Eigen::Matrix3f::Zero();
  for (std::size_t i = 0; i < count; ++i) {
    sigma.noalias() += (source(i) - mean_p) * (target(i) - mean_y).transpose();
  }
  sigma *= inverse;
  // Eq. 24: Sigma_py = U S V^T. With Sigma = sum p y^T the rotation taking p to y is V U^T;
  // Eq. 25 (printed for the transposed covariance, and with a typo in the matrix) corrects a
  // reflection by diag(1, 1, det(V U^T)).
  const Eigen::JacobiSVD<Eigen::Matrix3f> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3f& u = svd.matrixU();
  const Eigen::Matrix3f& v = svd.matrixV();
  Eigen::Vector3f diagonal(1.0F, 1.0F, (v * u.transpose()).determinant() < 0.0F ? -1.0F : 1.0F);
  Eigen::Isometry3f transform = Eigen::Isometry3f::Identity();
  transform.linear() = v * diagonal.asDiagonal() * u.transpose();
  // Eq. 26: t = mu_y - R mu_p.
  transform.translation() = mean_y - transform.linear() * mean_p;
  return transform;
}

}  // namespace

Eigen::Isometry3f fit_rigid(const Points& p, const Points& y, std::size_t count) {
  if (count < 3 || p.size() < count || y.size() < count) {
    throw std::invalid_argument("fit_rigid: need at least 3 pairs, got " + std::to_string(count));
  }
  return fit_pairs(
      count, [&](std::size_t i) -> const Eigen::Vector3f& { return p[i]; },
      [&](std::size_t i) -> const Eigen::Vector3f& { return y[i]; });
}

Icp::Icp(Points model_points_m, IcpConfig config, Points model_normals)
    : tree_(std::move(model_points_m)), normals_(std::move(model_normals)), config_(config) {
  if (tree_.size() < 3) {
    throw std::invalid_argument("Icp: the model needs at least 3 points, got " +
                                std::to_string(tree_.size()));
  }
  if (normals_.size() != tree_.size())
    normals_ = estimate_normals(tree_.points(), config_.normal_neighbours);
  double spacing = 0.0;
  for (const auto& p : tree_.points()) {
    std::uint32_t indices[2];
    float squared[2];
    if (tree_.knn(p, 2, indices, squared) == 2)
      spacing += std::sqrt(static_cast<double>(squared[1]));
  }
  model_spacing_m_ = static_cast<float>(spacing / static_cast<double>(tree_.size()));
  if (!(config_.inlier_distance_m > 0.0F)) config_.inlier_distance_m = model_spacing_m_;
  reserve(1024);
}

void Icp::reserve(std::size_t points) {
  source_.reserve(points);
  target_.reserve(points);
  squared_.reserve(points);
  median_scratch_.reserve(points);
}

void Icp::pair_up(const Points& p_camera, std::size_t step,
                  const Eigen::Isometry3f& T_model_camera) {
  // Eq. 21: closest model point y of every (sub-sampled) scene point p, in the model frame.
  const float max_squared =
      config_.max_correspondence_distance_m * config_.max_correspondence_distance_m;
  source_.resize(p_camera.size());
  target_.resize(p_camera.size());
  squared_.resize(p_camera.size());
  pairs_ = 0;
  for (std::size_t i = 0; i < p_camera.size(); i += step) {
    const Eigen::Vector3f p_model = T_model_camera * p_camera[i];
    const auto [index, squared] = tree_.nearest(p_model);
    if (squared > max_squared) continue;
    source_[pairs_] = p_model;
    target_[pairs_] = index;
    squared_[pairs_] = squared;
    ++pairs_;
  }
  trim();
}

std::size_t Icp::iterate(const Points& p_camera, std::size_t step,
                         Eigen::Isometry3f& T_model_camera) {
  pair_up(p_camera, step, T_model_camera);
  if (pairs_ < 3) return pairs_;
  const Points& model = tree_.points();

  Eigen::Isometry3f update = Eigen::Isometry3f::Identity();
  if (config_.metric == IcpMetric::point_to_point) {
    update = fit_pairs(
        pairs_, [&](std::size_t i) -> const Eigen::Vector3f& { return source_[i]; },
        [&](std::size_t i) -> const Eigen::Vector3f& { return model[target_[i]]; });
  } else {
    // Point-to-plane: minimise sum ((R p + t - y) . n_y)^2, linearised in a small rotation w.
    Eigen::Matrix<float, 6, 6> a = Eigen::Matrix<float, 6, 6>::Zero();
    Eigen::Matrix<float, 6, 1> b = Eigen::Matrix<float, 6, 1>::Zero();
    for (std::size_t i = 0; i < pairs_; ++i) {
      const Eigen::Vector3f& n = normals_[target_[i]];
      const Eigen::Vector3f moment = source_[i].cross(n);
      Eigen::Matrix<float, 6, 1> row;
      row(0) = moment.x();
      row(1) = moment.y();
      row(2) = moment.z();
      row.tail<3>() = n;
      const float residual = (source_[i] - model[target_[i]]).dot(n);
      a.noalias() += row * row.transpose();
      b.noalias() -= row * residual;
    }
    const Eigen::Matrix<float, 6, 1> x = a.ldlt().solve(b);
    const Eigen::Vector3f w = x.head<3>();
    const float angle = w.norm();
    if (angle > 1e-12F) update.linear() = Eigen::AngleAxisf(angle, w / angle).toRotationMatrix();
    update.translation() = x.tail<3>();
    if (!update.matrix().allFinite()) update = Eigen::Isometry3f::Identity();
  }
  T_model_camera = update * T_model_camera;
  for (std::size_t i = 0; i < pairs_; ++i) source_[i] = update * source_[i];
  return pairs_;
}

void Icp::evaluate(const Eigen::Isometry3f& /*T_model_camera*/, IcpResult& result) const {
  // Residuals of the last pairs after the last update (no extra nearest-neighbour pass).
  const Points& model = tree_.points();
  const float inlier_squared = config_.inlier_distance_m * config_.inlier_distance_m;
  double sum = 0.0;
  std::size_t inliers = 0;
  for (std::size_t i = 0; i < pairs_; ++i) {
    const float squared = (source_[i] - model[target_[i]]).squaredNorm();
    sum += static_cast<double>(squared);
    inliers += squared <= inlier_squared ? 1U : 0U;
  }
  result.correspondences = pairs_;
  result.inliers = inliers;
  result.rmse_m =
      pairs_ > 0 ? static_cast<float>(std::sqrt(sum / static_cast<double>(pairs_))) : 0.0F;
  result.valid = pairs_ >= 3;
}

void Icp::trim() {
  if (!(config_.trim_factor > 0.0F) || pairs_ < 6) return;
  // The median pair distance: the target's own pairs are the majority, so it is the sensor's
  // noise plus the guess's error; pairs far beyond it are another surface's.
  median_scratch_.assign(squared_.begin(), squared_.begin() + static_cast<std::ptrdiff_t>(pairs_));
  const auto middle = median_scratch_.begin() + static_cast<std::ptrdiff_t>(pairs_ / 2);
  std::nth_element(median_scratch_.begin(), middle, median_scratch_.end());
  const float limit_m = std::max(config_.trim_floor_m, config_.trim_factor * std::sqrt(*middle));
  const float limit_squared = limit_m * limit_m;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < pairs_; ++i) {
    if (squared_[i] > limit_squared) continue;
    source_[kept] = source_[i];
    target_[kept] = target_[i];
    squared_[kept] = squared_[i];
    ++kept;
  }
  pairs_ = kept;
}

IcpResult Icp::align(const Points& p_camera, const Eigen::Isometry3f& T_camera_model_guess) {
  return align(p_camera, T_camera_model_guess, config_.iterations);
}

IcpResult Icp::align(const Points& p_camera, const Eigen::Isometry3f& T_camera_model_guess,
                     const std::array<int, 3>& iterations) {
  IcpResult result;
  result.scene_points = p_camera.size();
  Eigen::Isometry3f T_model_camera = T_camera_model_guess.inverse();
  pairs_ = 0;
  constexpr std::array<std::size_t, 3> kSteps{4, 2, 1};  // 1/4, 1/2, all points
  for (std::size_t stage = 0; stage < 3; ++stage) {
    for (int k = 0; k < iterations[stage]; ++k) {
      const std::size_t pairs = iterate(p_camera, kSteps[stage], T_model_camera);
      ++result.iterations;
      if (pairs < 3) break;
    }
  }
  if (result.iterations == 0) {
    // Evaluation only: pair every scene point with its closest model point, no update.
    pair_up(p_camera, 1, T_model_camera);
  }
  evaluate(T_model_camera, result);
  result.T_camera_model = T_model_camera.inverse();
  return result;
}

}  // namespace avs::matching
