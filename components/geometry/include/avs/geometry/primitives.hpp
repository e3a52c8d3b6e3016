// Procedural meshes: boxes, cylinders, planes and surfaces of revolution, plus the small
// operations the built-in objects are assembled with. All sizes in metres.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "avs/geometry/mesh.hpp"

namespace avs::geometry {

/// One point of a lathe profile: distance from the axis and position along it.
struct ProfilePoint {
  double radius_m = 0;
  double height_m = 0;
};

/// Revolves `profile` about +Z with `segments` steps. A profile that starts and ends on the
/// axis (radius 0) gives a closed surface; it must run so that the outside is on its right
/// when walking from the first point to the last in the (radius, height) half-plane, e.g.
/// bottom pole -> outer wall upwards -> top pole.
Mesh make_lathe(const std::vector<ProfilePoint>& profile, int segments);

/// Axis-aligned box centred at the origin.
Mesh make_box(const Eigen::Vector3d& size_m);

/// Closed cylinder along Z, centred at the origin.
Mesh make_cylinder(double radius_m, double height_m, int segments = 64);

/// Rectangle in the XY plane, centred at the origin, facing +Z, split into a grid of
/// `divisions` x `divisions` quads.
Mesh make_plane(double width_m, double height_m, int divisions = 1);

/// Applies T to every vertex.
void transform(Mesh& mesh, const Eigen::Isometry3d& T);

/// Appends `part` to `mesh` (indices shifted).
void append(Mesh& mesh, const Mesh& part);

/// Total triangle area in m^2.
double surface_area(const Mesh& mesh);

/// Axis-aligned bounds: min (column 0) and max (column 1).
Eigen::Matrix<double, 3, 2> bounds(const Mesh& mesh);

}  // namespace avs::geometry
