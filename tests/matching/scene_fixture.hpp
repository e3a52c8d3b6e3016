// Shared test helpers: a built-in object's M-PCD and S-PCDs rendered at known poses.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "avs/matching/model_cloud.hpp"
#include "avs/matching/scene_cloud.hpp"
#include "avs/matching/synthetic.hpp"

namespace avs::matching::test {

inline constexpr float kDepthNoiseM = 0.0003F;  // 0.3 mm, seeded

/// The synthetic tests' camera: 512 x 512 pinhole, f = 900 px, principal point at the centre.
inline geometry::CameraModel test_camera() {
  return {
      .width = 512, .height = 512, .fx_px = 900.0, .fy_px = 900.0, .cx_px = 255.5, .cy_px = 255.5};
}

/// The paper's camera as decode::default_sensor_geometry() models it (f = 628.8 px).
inline geometry::CameraModel paper_camera() {
  geometry::CameraModel camera = test_camera();
  camera.fx_px = camera.fy_px = 628.8;
  return camera;
}

inline ModelCloud model_of(const ObjectPreset& object) {
  ModelCloudConfig config;
  config.target_points = object.model_points;
  return make_model_cloud(object.mesh, config);
}

inline SceneCloudConfig scene_config_of(const ObjectPreset& object, const ModelCloud& model) {
  SceneCloudConfig config;
  config.target_points = object.scene_points;
  config.voxel_size_m = model.voxel_size_m;
  return config;
}

/// Renders the object at T_camera_model, adds seeded noise, builds the S-PCD.
inline Points scene_of(const ObjectPreset& object, const ModelCloud& model,
                       const Eigen::Isometry3f& T_camera_model, std::uint32_t seed,
                       const geometry::CameraModel& camera = test_camera()) {
  DepthImage depth = render_depth(object.mesh, T_camera_model, camera);
  add_depth_noise(depth, kDepthNoiseM, seed);
  SceneCloudBuilder builder(scene_config_of(object, model));
  return builder.build(depth.view(), {}, camera);
}

/// What a hand holding the object adds to its S-PCD: the scene points of one side of the
/// object (y below the scene's `share` quantile) are hidden behind a flat face (a box's, facing
/// the camera) `gap_m` in front of the nearest of them, one point on each of their camera rays.
inline Points with_hand(const Points& scene, float gap_m, float share) {
  std::vector<float> ys;
  for (const auto& p : scene) ys.push_back(p.y());
  std::sort(ys.begin(), ys.end());
  const float below = ys[static_cast<std::size_t>(share * static_cast<float>(ys.size() - 1))];
  float nearest_z = std::numeric_limits<float>::max();
  for (const auto& p : scene) {
    if (p.y() <= below) nearest_z = std::min(nearest_z, p.z());
  }
  const float face_z = nearest_z - gap_m;
  Points out;
  for (const auto& p : scene)
    out.push_back(p.y() <= below ? Eigen::Vector3f(p * (face_z / p.z())) : p);
  return out;
}

inline Eigen::Isometry3f perturbed(const Eigen::Isometry3f& pose, const Eigen::Vector3f& offset_m,
                                   const Eigen::Vector3f& axis, float angle_deg) {
  Eigen::Isometry3f out = pose;
  out.translation() += offset_m;
  out.linear() =
      Eigen::AngleAxisf(angle_deg * 3.14159265F / 180.0F, axis.normalized()).toRotationMatrix() *
      pose.linear();
  return out;
}

}  // namespace avs::matching::test
