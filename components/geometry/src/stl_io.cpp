// STL reader (ASCII and binary) and writer. STL stores each facet's corners separately;
// bit-identical corners are merged into one vertex.
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <iterator>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "avs/geometry/mesh.hpp"
#include "mesh_io_detail.hpp"

namespace avs::geometry {
namespace {

/// Merges bit-identical corners.
class VertexMerger {
 public:
  explicit VertexMerger(Mesh& mesh) : mesh_(mesh) {}

  int add(const Eigen::Vector3f& p) {
    std::array<std::uint32_t, 3> key;
    std::memcpy(key.data(), p.data(), sizeof(key));
    const std::uint64_t h = (std::uint64_t{key[0]} * 0x9E3779B97F4A7C15ull) ^
                            (std::uint64_t{key[1]} * 0xC2B2AE3D27D4EB4Full) ^ key[2];
    auto& bucket = index_[h];
    for (int i : bucket) {
      if (mesh_.vertices[i] == p) return i;
    }
    mesh_.vertices.push_back(p);
    bucket.push_back(static_cast<int>(mesh_.vertices.size() - 1));
    return bucket.back();
  }

 private:
  Mesh& mesh_;
  std::unordered_map<std::uint64_t, std::vector<int>> index_;
};

Mesh read_binary(const std::vector<char>& bytes, const std::string& path) {
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  Mesh mesh;
  VertexMerger merger(mesh);
  for (std::uint32_t f = 0; f < count; ++f) {
    const char* record = bytes.data() + 84 + 50 * static_cast<std::size_t>(f);
    Eigen::Vector3i tri;
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3f p;
      std::memcpy(p.data(), record + 12 + 12 * c, 12);
      if (!p.allFinite()) detail::fail(path, 0, "facet " + std::to_string(f) + " is not finite");
      tri[c] = merger.add(p);
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

Mesh read_ascii(const std::vector<char>& bytes, const std::string& path) {
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  Mesh mesh;
  VertexMerger merger(mesh);
  std::string line;
  std::size_t line_number = 0;
  std::vector<int> corners;
  bool in_loop = false;
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "vertex") {
      if (!in_loop) detail::fail(path, line_number, "'vertex' outside 'outer loop'");
      Eigen::Vector3f p;
      if (!(words >> p.x() >> p.y() >> p.z())) {
        detail::fail(path, line_number, "expected three numbers after 'vertex'");
      }
      corners.push_back(merger.add(p));
    } else if (keyword == "outer") {
      in_loop = true;
      corners.clear();
    } else if (keyword == "endloop") {
      if (corners.size() < 3) {
        detail::fail(path, line_number,
                     "loop with " + std::to_string(corners.size()) + " vertices");
      }
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
      }
      in_loop = false;
    } else if (keyword == "solid" || keyword == "facet" || keyword == "endfacet" ||
               keyword == "endsolid" || keyword.empty()) {
      continue;
    } else {
      detail::fail(path, line_number, "unexpected keyword '" + keyword + "'");
    }
  }
  if (in_loop) detail::fail(path, line_number, "file ends inside a facet loop");
  return mesh;
}

Eigen::Vector3f facet_normal(const Mesh& mesh, const Eigen::Vector3i& t) {
  const Eigen::Vector3f n =
      (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
  const float norm = n.norm();
  return norm > 0 ? Eigen::Vector3f(n / norm) : Eigen::Vector3f::Zero();
}

}  // namespace

namespace detail {

Mesh load_stl(const std::string& path) {
  std::ifstream in = open_input(path);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  // Binary if the size matches the facet count; ASCII files start with "solid" but so do
  // some binary headers, hence the size test first.
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (bytes.size() == 84 + 50 * static_cast<std::size_t>(count)) return read_binary(bytes, path);
  }
  if (bytes.size() >= 5 && std::string(bytes.data(), 5) == "solid") return read_ascii(bytes, path);
  fail(path, 0,
       "neither ASCII STL (no leading 'solid') nor binary STL (size " +
           std::to_string(bytes.size()) + " does not match the facet count)");
}

}  // namespace detail

void save_stl(const Mesh& mesh, const std::string& path, bool binary) {
  std::ofstream out = detail::open_output(path);
  if (binary) {
    static_assert(std::endian::native == std::endian::little, "save_stl assumes little-endian");
    char header[80] = {};
    std::strncpy(header, "avs binary STL, metres", sizeof(header) - 1);
    out.write(header, 80);
    const auto count = static_cast<std::uint32_t>(mesh.triangles.size());
    out.write(reinterpret_cast<const char*>(&count), 4);
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3f n = facet_normal(mesh, t);
      out.write(reinterpret_cast<const char*>(n.data()), 12);
      for (int c = 0; c < 3; ++c)
        out.write(reinterpret_cast<const char*>(mesh.vertices[t[c]].data()), 12);
      const std::uint16_t attributes = 0;
      out.write(reinterpret_cast<const char*>(&attributes), 2);
    }
  } else {
    out << "solid avs\n" << std::setprecision(9);
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3f n = facet_normal(mesh, t);
      out << "facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n outer loop\n";
      for (int c = 0; c < 3; ++c) {
        const Eigen::Vector3f& p = mesh.vertices[t[c]];
        out << "  vertex " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
      }
      out << " endloop\nendfacet\n";
    }
    out << "endsolid avs\n";
  }
  if (!out) detail::fail(path, 0, "write failed");
}

}  // namespace avs::geometry
