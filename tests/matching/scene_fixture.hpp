// Shared test helpers: a built-in object's M-PCD and S-PCDs rendered at known poses.
#pragma once

#include <cstdint>

#include "avs/matching/model_cloud.hpp"
#include "avs/matching/scene_cloud.hpp"
#include "avs/matching/synthetic.hpp"

namespace avs::matching::test {

inline constexpr float kDepthNoiseM = 0.0003F;  // 0.3 mm, seeded

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
                       const CameraIntrinsics& camera = {}) {
  DepthImage depth = render_depth(object.mesh, T_camera_model, camera);
  add_depth_noise(depth, kDepthNoiseM, seed);
  SceneCloudBuilder builder(scene_config_of(object, model));
  return builder.build(depth.view(), {}, camera);
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
