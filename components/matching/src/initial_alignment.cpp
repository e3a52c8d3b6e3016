#include "avs/matching/initial_alignment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <Eigen/Eigenvalues>

namespace avs::matching {
namespace {

FeatureConfig with_radius(FeatureConfig config, float spacing_m) {
  if (!(config.neighbourhood_radius_m > 0.0F)) config.neighbourhood_radius_m = 2.5F * spacing_m;
  return config;
}

/// The shortest rotation taking `from` onto `to` (any lengths): the arithmetic of Eigen's
/// Quaternion::FromTwoVectors away from the antiparallel case. Eigen's antiparallel branch
/// instantiates a JacobiSVD that took a third of this file's compile time; here the half turn
/// is about any axis orthogonal to `from`, which serves the plane hypotheses (they scan the
/// in-plane angle anyway).
Eigen::Matrix3f rotation_onto(const Eigen::Vector3f& from, const Eigen::Vector3f& to) {
  const Eigen::Vector3f v0 = from.normalized();
  const Eigen::Vector3f v1 = to.normalized();
  const float c = v1.dot(v0);
  if (c < -1.0F + Eigen::NumTraits<float>::dummy_precision()) {
    return Eigen::AngleAxisf(std::numbers::pi_v<float>, v0.unitOrthogonal()).toRotationMatrix();
  }
  const float s = std::sqrt((1.0F + c) * 2.0F);
  Eigen::Quaternionf q;
  q.vec() = v0.cross(v1) * (1.0F / s);
  q.w() = s * 0.5F;
  return q.toRotationMatrix();
}

IcpConfig refine_config(const InitialAlignmentConfig& config) {
  IcpConfig icp;
  icp.iterations = config.refine_iterations;
  icp.max_correspondence_distance_m = config.score_truncation_m;
  icp.metric = config.refine_metric;
  icp.trim_factor = config.trim_factor;
  return icp;
}

// Eq. 20: T [L_s p; 0 1] = [L_m q; 0 1]  =>  T = [L_m L_s^T, q - L_m L_s^T p], scene -> model.
Eigen::Isometry3f lrf_transform(const Lrf& scene, const Lrf& model) {
  Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
  t.linear() = model.axes * scene.axes.transpose();
  t.translation() = model.origin_m - t.linear() * scene.origin_m;
  return t;
}

using Clock = std::chrono::steady_clock;
float ms_since(Clock::time_point start) {
  return std::chrono::duration<float, std::milli>(Clock::now() - start).count();
}

bool similar(const Eigen::Isometry3f& a, const Eigen::Isometry3f& b) {
  const Eigen::Matrix3f d = a.linear().transpose() * b.linear();
  return (a.translation() - b.translation()).norm() < 0.01F &&
         d.trace() > 1.0F + 2.0F * std::cos(0.2F);
}

}  // namespace

namespace detail {

// A coarse range image of the scene over the normalised image plane (x/z, y/z): per cell, the
// nearest depth of the scene points splatted into it and its 8 neighbours (cells about one point
// spacing wide, so the sparse S-PCD covers its silhouette without holes).
class RangeImage {
 public:
  static constexpr float kMinDepthM = 1e-3F;  // points closer (or behind the camera) are ignored
  RangeImage(const Points& p_camera, float spacing_m) {
    float z_sum = 0.0F;
    std::size_t in_front = 0;
    Eigen::Vector2f low(std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
    Eigen::Vector2f high = -low;
    for (const auto& p : p_camera) {
      if (!(p.z() > kMinDepthM)) continue;
      z_sum += p.z();
      ++in_front;
      const Eigen::Vector2f uv = p.head<2>() / p.z();
      low = low.cwiseMin(uv);
      high = high.cwiseMax(uv);
    }
    if (in_front == 0 || !(spacing_m > 0.0F)) return;  // empty: the scene shows nothing
    const float z_mean = z_sum / static_cast<float>(in_front);
    inverse_cell_ = z_mean / spacing_m;
    origin_ = low.array() - 2.0F / inverse_cell_;
    width_ = static_cast<int>((high.x() - origin_.x()) * inverse_cell_) + 3;
    height_ = static_cast<int>((high.y() - origin_.y()) * inverse_cell_) + 3;
    depth_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_),
                  std::numeric_limits<float>::infinity());
    for (const auto& p : p_camera) {
      if (!(p.z() > kMinDepthM)) continue;
      const int u = static_cast<int>((p.x() / p.z() - origin_.x()) * inverse_cell_);
      const int v = static_cast<int>((p.y() / p.z() - origin_.y()) * inverse_cell_);
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          float& cell = depth_[static_cast<std::size_t>((v + dv) * width_ + u + du)];
          cell = std::min(cell, p.z());
        }
      }
    }
  }
  /// Nearest scene depth along the ray of p; infinity where the scene shows nothing.
  [[nodiscard]] float depth(const Eigen::Vector3f& p) const {
    if (!(p.z() > kMinDepthM)) return std::numeric_limits<float>::infinity();
    const float u = (p.x() / p.z() - origin_.x()) * inverse_cell_;
    const float v = (p.y() / p.z() - origin_.y()) * inverse_cell_;
    if (!(u >= 0.0F && v >= 0.0F && u < static_cast<float>(width_) &&
          v < static_cast<float>(height_))) {
      return std::numeric_limits<float>::infinity();
    }
    return depth_[static_cast<std::size_t>(static_cast<int>(v) * width_ + static_cast<int>(u))];
  }

 private:
  std::vector<float> depth_;
  Eigen::Vector2f origin_ = Eigen::Vector2f::Zero();
  float inverse_cell_ = 1.0F;
  int width_ = 0;
  int height_ = 0;
};

}  // namespace detail

InitialAligner::InitialAligner(const ModelCloud& model, InitialAlignmentConfig config)
    : config_(config),
      model_tree_(model.points_m),
      dense_tree_(model.dense_points_m.empty() ? model.points_m : model.dense_points_m),
      dense_normals_(model.dense_points_m.empty() ? model.normals : model.dense_normals),
      distance_(dense_tree_.points(), config.distance_cell_m, config.score_truncation_m),
      refine_(model.points_m, refine_config(config), model.normals),
      verify_(
          dense_tree_.points(),
          [&] {
            IcpConfig icp = refine_config(config);
            icp.iterations = config.verify_iterations;
            return icp;
          }(),
          dense_normals_) {
  spacing_m_ = model.mean_spacing_m;
  config_.scene_features = with_radius(config_.scene_features, model.mean_spacing_m);
  config_.model_features = with_radius(config_.model_features, model.mean_spacing_m);
  // Principal axes of the model through its centroid, for the flip candidates.
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto& p : model.points_m) centroid += p;
  centroid /= static_cast<float>(std::max<std::size_t>(1, model.points_m.size()));
  Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
  for (const auto& p : model.points_m)
    covariance.noalias() += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> principal(covariance);
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Isometry3f flip = Eigen::Isometry3f::Identity();
    flip.linear() = Eigen::AngleAxisf(std::numbers::pi_v<float>, principal.eigenvectors().col(axis))
                        .toRotationMatrix();
    flip.translation() = centroid - flip.linear() * centroid;
    flips_model_[static_cast<std::size_t>(axis)] = flip;
  }
  NormalOrientation outward;
  outward.reference_normals = &model.normals;
  const PointFeatures features =
      compute_features(model.points_m, model_tree_, config_.model_features, outward);
  model_lrfs_ = compute_lrfs(model.points_m, features, config_.model_features);
  // Flat faces for the plane hypotheses (our addition): the mesh's outward normals where the
  // voxel has one, else the oriented Eq. 18 normals.
  Points face_normals = features.normals;
  for (std::size_t i = 0; i < face_normals.size() && i < model.normals.size(); ++i) {
    if (!model.normals[i].isZero()) face_normals[i] = model.normals[i].normalized();
  }
  if (config_.plane_rotations > 0) {
    model_faces_ =
        find_planar_patches(model.points_m, face_normals, config_.model_faces, spacing_m_);
  }
}

float InitialAligner::score(const Points& p_camera, const std::vector<std::uint32_t>& subset,
                            const Eigen::Isometry3f& T_model_camera, float give_up_above) const {
  // The subset is in random order, so after k of n points the partial sum estimates k/n of the
  // total: a hypothesis whose first `probe` points already cost more than `slack` times their
  // share of the current limit is abandoned too (early termination of the pair scoring).
  const std::size_t probe = config_.score_probe_points;
  const float slack = config_.score_probe_slack;
  const std::size_t n = subset.size();
  const float probe_limit =
      std::isfinite(give_up_above) && n > probe
          ? slack * give_up_above * static_cast<float>(probe) / static_cast<float>(n)
          : std::numeric_limits<float>::infinity();
  float sum = 0.0F;
  for (std::size_t k = 0; k < n; ++k) {
    sum += distance_.nearest_distance(T_model_camera * p_camera[subset[k]]);
    if (sum > give_up_above || (k + 1 == probe && sum > probe_limit))
      return std::numeric_limits<float>::infinity();
  }
  return sum;
}

InitialAlignmentResult InitialAligner::align(const Points& p_camera) {
  InitialAlignmentResult result;
  scene_lrfs_.clear();
  scene_lrfs_used_.clear();
  if (p_camera.size() < 10 || (model_lrfs_.empty() && model_faces_.empty())) return result;

  auto start = Clock::now();
  // 1. Scene features and LRFs (normals toward the camera at the origin).
  const KdTree scene_tree(p_camera);
  const PointFeatures features = compute_features(p_camera, scene_tree, config_.scene_features, {});
  scene_lrfs_ = compute_lrfs(p_camera, features, config_.scene_features);
  // Large planar scene patches (normals toward the camera) for the plane hypotheses.
  std::vector<PlanarPatch> scene_planes;
  if (config_.plane_rotations > 0 && !model_faces_.empty()) {
    scene_planes =
        find_planar_patches(p_camera, features.normals, config_.scene_planes, spacing_m_);
  }
  result.scene_planes = scene_planes.size();
  if (scene_lrfs_.empty() && scene_planes.empty()) return result;

  // 2. Down-sample the scene LRFs (rate 0.1 in the paper), seeded and without repetition.
  std::vector<std::size_t> order(scene_lrfs_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::mt19937 rng(config_.seed);
  std::shuffle(order.begin(), order.end(), rng);
  const auto wanted = std::max<std::size_t>(
      config_.min_scene_lrfs,
      static_cast<std::size_t>(
          std::ceil(config_.scene_lrf_rate * static_cast<float>(scene_lrfs_.size()))));
  order.resize(std::min(order.size(), wanted));
  for (const auto i : order) scene_lrfs_used_.push_back(scene_lrfs_[i]);

  result.features_ms = ms_since(start);
  start = Clock::now();
  // 3. Score every scene/model LRF pair by summed (truncated) closest-point distances on an
  //    evenly spread subset of the scene; keep the best few distinct hypotheses.
  std::vector<std::uint32_t> subset;
  const std::size_t step = std::max<std::size_t>(1, p_camera.size() / config_.score_points);
  for (std::size_t i = 0; i < p_camera.size(); i += step)
    subset.push_back(static_cast<std::uint32_t>(i));
  // Random order: a partial sum then already samples the whole object, so a wrong hypothesis
  // is abandoned after a few points.
  std::shuffle(subset.begin(), subset.end(), rng);
  // Scores a hypothesis into `list` (sorted ascending, at most `keep`), abandoning it once it
  // costs more than the list's worst.
  const auto offer = [&](std::vector<Hypothesis>& list, std::size_t keep,
                         const Eigen::Isometry3f& T_model_camera) {
    const float limit =
        list.size() < keep ? std::numeric_limits<float>::infinity() : list.back().score;
    const float s = score(p_camera, subset, T_model_camera, limit);
    if (!(s < limit)) return;
    const auto at =
        std::lower_bound(list.begin(), list.end(), s,
                         [](const Hypothesis& h, float value) { return h.score < value; });
    list.insert(at, {T_model_camera, s});
    if (list.size() > keep) list.pop_back();
  };
  std::vector<Hypothesis> best;  // at most refine_candidates * 4
  const std::size_t keep = std::max<std::size_t>(1, config_.refine_candidates) * 4;
  for (const auto& scene : scene_lrfs_used_) {
    for (const auto& model : model_lrfs_) {
      offer(best, keep, lrf_transform(scene, model));
      ++result.hypotheses;
    }
  }
  // 3b. Plane hypotheses (our addition beyond the paper's Eq. 20 LRF pairs): each planar scene
  //     patch against each flat model face, the face's outward normal turned onto the patch's
  //     normal (which faces the camera) and the centroids matched, at plane_rotations turns about
  //     the normal (the in-plane angle is free); scored like the LRF pairs, kept apart so a flat
  //     scene's right pose is refined and verified even when LRF pairs score better on the
  //     subset.
  std::vector<Hypothesis> plane_best;  // at most plane_candidates * 4
  const std::size_t plane_keep = std::max<std::size_t>(1, config_.plane_candidates) * 4;
  const float turn = 2.0F * std::numbers::pi_v<float> /
                     static_cast<float>(std::max<std::size_t>(1, config_.plane_rotations));
  for (const auto& scene : scene_planes) {
    for (const auto& face : model_faces_) {
      const Eigen::Matrix3f onto = rotation_onto(face.normal, scene.normal);
      for (std::size_t r = 0; r < config_.plane_rotations; ++r) {
        Eigen::Isometry3f T_camera_model = Eigen::Isometry3f::Identity();
        T_camera_model.linear() =
            Eigen::AngleAxisf(turn * static_cast<float>(r), scene.normal).toRotationMatrix() * onto;
        T_camera_model.translation() = scene.centroid_m - T_camera_model.linear() * face.centroid_m;
        offer(plane_best, plane_keep, T_camera_model.inverse());
        ++result.plane_hypotheses;
      }
    }
  }
  result.scene_lrfs = scene_lrfs_used_.size();
  result.model_lrfs = model_lrfs_.size();
  if (best.empty() && plane_best.empty()) return result;

  result.scoring_ms = ms_since(start);
  start = Clock::now();
  // 4. Verify: the best distinct hypotheses, and the best few turned end-for-end, are refined by
  //    ICP and screened by the scene's distance to the model; the best of those are scored by
  //    that distance plus what the pose predicts must be seen (free space), the best kept.
  std::vector<Eigen::Isometry3f> distinct;
  for (const auto& h : best) {
    if (distinct.size() >= config_.refine_candidates) break;
    if (std::none_of(distinct.begin(), distinct.end(),
                     [&](const auto& d) { return similar(d, h.T_model_camera); })) {
      distinct.push_back(h.T_model_camera);
    }
  }
  const std::size_t unflipped = distinct.size();
  for (std::size_t c = 0; c < std::min(config_.flip_candidates, unflipped); ++c) {
    // T_model_camera of a flipped pose: flip^-1 applied in the model frame.
    for (const auto& flip : flips_model_) distinct.push_back(flip.inverse() * distinct[c]);
  }
  // The best distinct plane hypotheses join them (our addition, see 3b).
  std::size_t planes_added = 0;
  for (const auto& h : plane_best) {
    if (planes_added >= config_.plane_candidates) break;
    if (std::none_of(distinct.begin(), distinct.end(),
                     [&](const auto& d) { return similar(d, h.T_model_camera); })) {
      distinct.push_back(h.T_model_camera);
      ++planes_added;
    }
  }
  // 4a. Refine every candidate by ICP on the M-PCD and screen it by the mean truncated distance
  //     from the scene to the dense model surface (tabulated).
  std::vector<Hypothesis> screened;
  screened.reserve(distinct.size());
  for (const auto& T_model_camera : distinct) {
    const IcpResult coarse = refine_.align(p_camera, T_model_camera.inverse());
    const Eigen::Isometry3f T_refined = coarse.T_camera_model.inverse();
    screened.push_back({T_refined, scene_distance(p_camera, T_refined)});
  }
  std::sort(screened.begin(), screened.end(),
            [](const Hypothesis& a, const Hypothesis& b) { return a.score < b.score; });
  if (screened.size() > config_.verify_candidates) screened.resize(config_.verify_candidates);

  // 4b. The best few: ICP on the dense samples, then the full score (scene term plus the
  //     free-space and visibility terms), keep the best.
  const detail::RangeImage range(p_camera, spacing_m_);
  float best_score = std::numeric_limits<float>::infinity();
  for (const auto& candidate : screened) {
    const VerifiedPose verified =
        verify(p_camera, scene_tree, range, candidate.T_model_camera.inverse());
    if (verified.score_m < best_score) {
      best_score = verified.score_m;
      result.T_camera_model = verified.T_camera_model;
      result.rmse_m = verified.rmse_m;
    }
  }
  result.candidates = distinct.size();
  result.score_m = best_score;
  result.verify_ms = ms_since(start);
  result.valid = true;
  return result;
}

float InitialAligner::scene_distance(const Points& p_camera,
                                     const Eigen::Isometry3f& T_model_camera) {
  // Mean truncated distance from the scene to the dense model surface (interpolated table),
  // over the score_trim_fraction of the scene points closest to it.
  distances_m_.resize(p_camera.size());
  for (std::size_t i = 0; i < p_camera.size(); ++i) {
    distances_m_[i] =
        std::min(distance_.distance(T_model_camera * p_camera[i]), config_.verify_truncation_m);
  }
  const auto kept = std::clamp<std::size_t>(
      static_cast<std::size_t>(
          std::ceil(config_.score_trim_fraction * static_cast<float>(p_camera.size()))),
      1, p_camera.size());
  if (kept < p_camera.size()) {
    std::nth_element(distances_m_.begin(), distances_m_.begin() + static_cast<std::ptrdiff_t>(kept),
                     distances_m_.end());
  }
  float sum = 0.0F;
  for (std::size_t i = 0; i < kept; ++i) sum += distances_m_[i];
  return sum / static_cast<float>(kept);
}

VerifiedPose InitialAligner::verify(const Points& p_camera,
                                    const Eigen::Isometry3f& T_camera_model_guess) {
  if (p_camera.empty()) return {};
  const KdTree scene_tree(p_camera);
  const detail::RangeImage range(p_camera, spacing_m_);
  return verify(p_camera, scene_tree, range, T_camera_model_guess);
}

VerifiedPose InitialAligner::verify(const Points& p_camera, const KdTree& scene_tree,
                                    const detail::RangeImage& range,
                                    const Eigen::Isometry3f& T_camera_model_guess) {
  VerifiedPose out;
  const IcpResult refined = verify_.align(p_camera, T_camera_model_guess);
  out.T_camera_model = refined.T_camera_model;
  out.rmse_m = refined.rmse_m;
  const Eigen::Isometry3f& T_camera_model = out.T_camera_model;
  const Eigen::Isometry3f T_model_camera = T_camera_model.inverse();
  out.scene_term_m = scene_distance(p_camera, T_model_camera);
  out.score_m = out.scene_term_m;
  // Model points the pose shows to the camera (normal toward it).
  const auto faces_camera = [&](std::size_t i, const Eigen::Vector3f& p) {
    return (T_camera_model.linear() * dense_normals_[i]).dot(p) < 0.0F;
  };
  if (config_.free_space_weight > 0.0F) {
    // Free space: those points must not lie where the scene shows nothing or in front of the
    // observed surface (hidden behind it is fine).
    const float tolerance = config_.free_space_tolerance_m;
    std::size_t counted = 0;
    std::size_t violations = 0;
    for (std::size_t i = 0; i < dense_tree_.size(); ++i) {
      const Eigen::Vector3f p = T_camera_model * dense_tree_.points()[i];
      if (!faces_camera(i, p)) continue;
      const float observed = range.depth(p);
      if (p.z() > observed + tolerance) continue;  // behind the observed surface
      ++counted;
      violations += p.z() < observed - tolerance ? 1U : 0U;
    }
    if (counted > 0)
      out.free_space_violations = static_cast<float>(violations) / static_cast<float>(counted);
    out.score_m +=
        config_.free_space_weight * config_.verify_truncation_m * out.free_space_violations;
  }
  if (config_.visibility_weight > 0.0F) {
    // Visibility: mean truncated distance from those points to the scene.
    const float verify_squared = config_.verify_truncation_m * config_.verify_truncation_m;
    float visible_sum = 0.0F;
    std::size_t visible = 0;
    for (std::size_t i = 0; i < dense_tree_.size(); ++i) {
      const Eigen::Vector3f p = T_camera_model * dense_tree_.points()[i];
      if (!faces_camera(i, p)) continue;
      visible_sum += std::sqrt(std::min(scene_tree.nearest(p).second, verify_squared));
      ++visible;
    }
    if (visible > 0)
      out.score_m += config_.visibility_weight * visible_sum / static_cast<float>(visible);
  }
  return out;
}

}  // namespace avs::matching
