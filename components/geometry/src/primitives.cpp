// Procedural meshes (see primitives.hpp).
#include "avs/geometry/primitives.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace avs::geometry {

Mesh make_lathe(const std::vector<ProfilePoint>& profile, int segments) {
  if (profile.size() < 2 || segments < 3) {
    throw std::invalid_argument("make_lathe: need at least 2 profile points and 3 segments, got " +
                                std::to_string(profile.size()) + " and " +
                                std::to_string(segments));
  }
  Mesh mesh;
  // first_index[i]: index of ring i's first vertex (a pole has one vertex).
  std::vector<int> first_index(profile.size());
  for (std::size_t i = 0; i < profile.size(); ++i) {
    first_index[i] = static_cast<int>(mesh.vertices.size());
    const auto r = static_cast<float>(profile[i].radius_m);
    const auto h = static_cast<float>(profile[i].height_m);
    if (profile[i].radius_m <= 0) {
      mesh.vertices.emplace_back(0.f, 0.f, h);
      continue;
    }
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      mesh.vertices.emplace_back(r * static_cast<float>(std::cos(phi)),
                                 r * static_cast<float>(std::sin(phi)), h);
    }
  }
  auto at = [&](std::size_t i, int j) {
    return profile[i].radius_m <= 0 ? first_index[i] : first_index[i] + (j % segments);
  };
  // Outward normal of (P(i,j), P(i,j+1), P(i+1,j+1)) is t_phi x t_profile (see header).
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    const bool pole_a = profile[i].radius_m <= 0, pole_b = profile[i + 1].radius_m <= 0;
    if (pole_a && pole_b) continue;
    for (int j = 0; j < segments; ++j) {
      if (!pole_a) mesh.triangles.emplace_back(at(i, j), at(i, j + 1), at(i + 1, j + 1));
      if (!pole_b) mesh.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i + 1, j));
    }
  }
  return mesh;
}

Mesh make_box(const Eigen::Vector3d& size_m) {
  Mesh mesh;
  const Eigen::Vector3f h = (size_m / 2).cast<float>();
  for (int k = 0; k < 8; ++k) {
    mesh.vertices.emplace_back((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                               (k & 4) ? h.z() : -h.z());
  }
  // Two triangles per face, counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.emplace_back(f[0], f[1], f[2]);
    mesh.triangles.emplace_back(f[0], f[2], f[3]);
  }
  return mesh;
}

Mesh make_cylinder(double radius_m, double height_m, int segments) {
  return make_lathe(
      {{0, -height_m / 2}, {radius_m, -height_m / 2}, {radius_m, height_m / 2}, {0, height_m / 2}},
      segments);
}

Mesh make_plane(double width_m, double height_m, int divisions) {
  if (divisions < 1) throw std::invalid_argument("make_plane: divisions must be >= 1");
  Mesh mesh;
  const int n = divisions + 1;
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      mesh.vertices.emplace_back(static_cast<float>(width_m * (double(ix) / divisions - 0.5)),
                                 static_cast<float>(height_m * (double(iy) / divisions - 0.5)),
                                 0.f);
    }
  }
  for (int iy = 0; iy < divisions; ++iy) {
    for (int ix = 0; ix < divisions; ++ix) {
      const int v00 = iy * n + ix, v10 = v00 + 1, v01 = v00 + n, v11 = v01 + 1;
      mesh.triangles.emplace_back(v00, v10, v11);
      mesh.triangles.emplace_back(v00, v11, v01);
    }
  }
  return mesh;
}

void transform(Mesh& mesh, const Eigen::Isometry3d& T) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (Eigen::Vector3f& v : mesh.vertices) v = Tf * v;
}

void append(Mesh& mesh, const Mesh& part) {
  const int offset = static_cast<int>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const Eigen::Vector3i& t : part.triangles) {
    mesh.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  }
}

double surface_area(const Mesh& mesh) {
  double area = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    area += 0.5 * (mesh.vertices[t[1]].cast<double>() - a)
                      .cross(mesh.vertices[t[2]].cast<double>() - a)
                      .norm();
  }
  return area;
}

Eigen::Matrix<double, 3, 2> bounds(const Mesh& mesh) {
  Eigen::Matrix<double, 3, 2> b;
  b.col(0).setConstant(mesh.vertices.empty() ? 0 : INFINITY);
  b.col(1).setConstant(mesh.vertices.empty() ? 0 : -INFINITY);
  for (const Eigen::Vector3f& v : mesh.vertices) {
    b.col(0) = b.col(0).cwiseMin(v.cast<double>());
    b.col(1) = b.col(1).cwiseMax(v.cast<double>());
  }
  return b;
}

}  // namespace avs::geometry
