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
/// Polygons with more than three vertices are split into triangle fans; STL vertices that are
/// bit-identical are merged.
Mesh load_mesh(const std::string& path);

/// Writes a binary little-endian PLY (float x y z, uchar/int vertex_indices).
void save_ply(const Mesh& mesh, const std::string& path);

/// Writes an STL file, binary (default) or ASCII; facet normals from the winding.
void save_stl(const Mesh& mesh, const std::string& path, bool binary = true);

/// Writes a Wavefront OBJ file (v and f records only).
void save_obj(const Mesh& mesh, const std::string& path);

}  // namespace avs::geometry
