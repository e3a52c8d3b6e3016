// Writes the built-in models as binary PLY files:  avs_make_models <output dir>
// (the shipped files are models/<name>.ply; tests/sim checks they match this generator).
#include <exception>
#include <iostream>
#include <string>

#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/primitives.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " <output directory>\n";
    return 2;
  }
  try {
    for (const std::string& name : avs::geometry::builtin_model_names()) {
      const avs::geometry::Mesh mesh = avs::geometry::make_builtin_model(name);
      const std::string path = std::string(argv[1]) + "/" + name + ".ply";
      avs::geometry::save_ply(mesh, path);
      const auto b = avs::geometry::bounds(mesh);
      std::cout << path << ": " << mesh.vertices.size() << " vertices, " << mesh.triangles.size()
                << " triangles, extent " << (b.col(1) - b.col(0)).transpose() << " m\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "avs_make_models: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
