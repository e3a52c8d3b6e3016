// Scenes: meshes with albedo and a trajectory each, and their ground truth at any time
// (world and camera frames, with the head state that placed the camera).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "avs/geometry/mesh.hpp"
#include "avs/sim/head.hpp"
#include "avs/sim/trajectory.hpp"

namespace avs::sim {

struct SceneObject {
  std::string name;
  std::shared_ptr<const geometry::Mesh> mesh;
  double albedo = 0.7;  ///< fraction of light reflected (Lambertian)
  std::shared_ptr<const Trajectory> trajectory;
};

struct Scene {
  std::vector<SceneObject> objects;
  /// Index of the object called `name`, -1 if none.
  int find(const std::string& name) const;
};

struct ObjectTruth {
  std::string name;
  Eigen::Isometry3d T_world_object = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_camera_object = Eigen::Isometry3d::Identity();
  Twist twist_world;
};

struct GroundTruth {
  double time_s = 0;
  HeadState head;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  std::vector<ObjectTruth> objects;
};

/// Every object's pose at t_s seen from the camera placed by `head_state`.
GroundTruth ground_truth(const Scene& scene, const HeadConfig& head, double t_s,
                         const HeadState& head_state);

/// A background plane (our addition; the paper's scenes are a lab): `width_m` x `height_m`,
/// facing the head (-X) at `distance_m` in front of it, centred on the world X axis.
SceneObject make_background_plane(double distance_m = 2.0, double width_m = 4.0,
                                  double height_m = 3.0, double albedo = 0.5);

}  // namespace avs::sim
