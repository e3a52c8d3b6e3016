// Test scene shared by the renderer tests: a plane facing the camera.
#pragma once

#include <numbers>

#include <Eigen/Geometry>

#include "avs/geometry/mesh.hpp"
#include "avs/sim/renderer.hpp"

namespace avs::sim::test {

/// `mesh` (a make_plane() in its xy plane) at camera-frame z = distance_m, facing the camera.
inline RenderObject facing_plane(const geometry::Mesh& mesh, double distance_m,
                                 double albedo = 0.6) {
  RenderObject o;
  o.mesh = &mesh;
  o.T_camera_object = Eigen::Translation3d(0, 0, distance_m) *
                      Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());  // faces -z
  o.albedo = albedo;
  return o;
}

}  // namespace avs::sim::test
