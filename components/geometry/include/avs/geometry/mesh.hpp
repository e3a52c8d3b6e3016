// Triangle meshes: loaded from PLY, STL or OBJ so users can add their own objects.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace avs::geometry {

/// Vertices in metres, triangles as vertex indices (counter-clockwise seen from outside).
struct Mesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
};

/// Loads a PLY (ASCII or binary little-endian), STL (ASCII or binary) or OBJ file, chosen by
/// extension. Throws std::runtime_error naming the file (and line, for text formats) on error.
Mesh load_mesh(const std::string& path);

/// Writes a binary little-endian PLY.
void save_ply(const Mesh& mesh, const std::string& path);

}  // namespace avs::geometry
