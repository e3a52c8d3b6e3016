// Shared helpers of the mesh readers and writers (not installed).
#pragma once

#include <cstddef>
#include <fstream>
#include <stdexcept>
#include <string>

#include "avs/geometry/mesh.hpp"

namespace avs::geometry::detail {

/// "path:line: what" (line 0 = no line).
[[noreturn]] inline void fail(const std::string& path, std::size_t line, const std::string& what) {
  throw std::runtime_error(line > 0 ? path + ":" + std::to_string(line) + ": " + what
                                    : path + ": " + what);
}

inline std::ifstream open_input(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, 0, "cannot open for reading");
  return in;
}

inline std::ofstream open_output(const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) fail(path, 0, "cannot open for writing");
  return out;
}

/// Checks every index of every triangle against the vertex count.
inline void check_indices(const Mesh& mesh, const std::string& path) {
  const int n = static_cast<int>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int i = mesh.triangles[t][c];
      if (i < 0 || i >= n) {
        fail(path, 0,
             "triangle " + std::to_string(t) + " uses vertex " + std::to_string(i) + " but only " +
                 std::to_string(n) + " vertices exist");
      }
    }
  }
}

Mesh load_ply(const std::string& path);
Mesh load_stl(const std::string& path);
Mesh load_obj(const std::string& path);

}  // namespace avs::geometry::detail
