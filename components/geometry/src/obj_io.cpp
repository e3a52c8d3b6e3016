// Wavefront OBJ reader (v and f records; vt, vn, groups and materials are ignored) and writer.
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "avs/geometry/mesh.hpp"
#include "mesh_io_detail.hpp"

namespace avs::geometry {
namespace {

/// Parses the vertex part of "i", "i/t", "i//n" or "i/t/n"; negative indices count from the end.
int parse_face_index(const std::string& token, int vertex_count, const std::string& path,
                     std::size_t line) {
  const std::string head = token.substr(0, token.find('/'));
  std::size_t used = 0;
  int index = 0;
  try {
    index = std::stoi(head, &used);
  } catch (const std::exception&) {
    detail::fail(path, line, "bad face index '" + token + "'");
  }
  if (used != head.size() || index == 0) detail::fail(path, line, "bad face index '" + token + "'");
  const int zero_based = index > 0 ? index - 1 : vertex_count + index;
  if (zero_based < 0 || zero_based >= vertex_count) {
    detail::fail(path, line,
                 "face index " + std::to_string(index) + " out of range (" +
                     std::to_string(vertex_count) + " vertices so far)");
  }
  return zero_based;
}

}  // namespace

namespace detail {

Mesh load_obj(const std::string& path) {
  std::ifstream in = open_input(path);
  Mesh mesh;
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "v") {
      Eigen::Vector3f p;
      if (!(words >> p.x() >> p.y() >> p.z())) {
        fail(path, line_number, "expected three numbers after 'v'");
      }
      mesh.vertices.push_back(p);
    } else if (keyword == "f") {
      std::vector<int> corners;
      std::string token;
      while (words >> token) {
        corners.push_back(
            parse_face_index(token, static_cast<int>(mesh.vertices.size()), path, line_number));
      }
      if (corners.size() < 3) {
        fail(path, line_number, "face with " + std::to_string(corners.size()) + " vertices");
      }
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
      }
    }
  }
  return mesh;
}

}  // namespace detail

void save_obj(const Mesh& mesh, const std::string& path) {
  std::ofstream out = detail::open_output(path);
  out << "# avs mesh, metres\n" << std::setprecision(9);
  for (const Eigen::Vector3f& p : mesh.vertices) {
    out << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  }
  if (!out) detail::fail(path, 0, "write failed");
}

}  // namespace avs::geometry
