// Scenes and ground truth (see scene.hpp).
#include "avs/sim/scene.hpp"

#include <numbers>

#include "avs/geometry/primitives.hpp"

namespace avs::sim {

int Scene::find(const std::string& name) const {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

GroundTruth ground_truth(const Scene& scene, const HeadConfig& head, double t_s,
                         const HeadState& head_state) {
  GroundTruth truth;
  truth.time_s = t_s;
  truth.head = head_state;
  truth.T_world_camera = T_world_camera(head, head_state.pan_rad, head_state.tilt_rad);
  const Eigen::Isometry3d T_camera_world = truth.T_world_camera.inverse();
  for (const SceneObject& object : scene.objects) {
    ObjectTruth o;
    o.name = object.name;
    o.T_world_object = object.trajectory->T_world_object(t_s);
    o.T_camera_object = T_camera_world * o.T_world_object;
    o.twist_world = twist_at(*object.trajectory, t_s);
    truth.objects.push_back(std::move(o));
  }
  return truth;
}

SceneObject make_background_plane(double distance_m, double width_m, double height_m,
                                  double albedo) {
  // make_plane faces +Z in its frame: carry +Z to world -X (towards the head), plane x to
  // world -Y (the head's right), plane y to world Z (a proper rotation: -Y x Z = -X).
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  R << 0, 0, -1,  //
      -1, 0, 0,   //
      0, 1, 0;
  T.linear() = R;
  T.translation() = Eigen::Vector3d(distance_m, 0, 0);
  SceneObject plane;
  plane.name = "background";
  plane.mesh = std::make_shared<const geometry::Mesh>(geometry::make_plane(width_m, height_m, 1));
  plane.albedo = albedo;
  plane.trajectory = std::make_shared<StaticTrajectory>(T);
  return plane;
}

}  // namespace avs::sim
