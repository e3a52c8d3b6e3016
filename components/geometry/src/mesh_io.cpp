// load_mesh: picks the reader from the file extension.
#include <algorithm>
#include <cctype>
#include <string>

#include "avs/geometry/mesh.hpp"
#include "mesh_io_detail.hpp"

namespace avs::geometry {

Mesh load_mesh(const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  Mesh mesh;
  if (ext == "ply") {
    mesh = detail::load_ply(path);
  } else if (ext == "stl") {
    mesh = detail::load_stl(path);
  } else if (ext == "obj") {
    mesh = detail::load_obj(path);
  } else {
    detail::fail(path, 0, "unknown mesh extension '" + ext + "' (expected .ply, .stl or .obj)");
  }
  detail::check_indices(mesh, path);
  if (mesh.triangles.empty()) detail::fail(path, 0, "mesh has no triangles");
  return mesh;
}

}  // namespace avs::geometry
