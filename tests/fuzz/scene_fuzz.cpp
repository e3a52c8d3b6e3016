// libFuzzer target: the scene parser (parse_scene). Errors are std::runtime_error naming
// "scene.yaml:line:col"; nothing else may escape. Built-in models come from a scratch folder
// of one-triangle meshes (the shipped models would make every input slow), and relative
// mesh paths resolve there too.
#include <stdexcept>

#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/mesh.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "fuzz_support.hpp"

namespace {

const avs::fuzz::ScratchDir& models() {
  static const avs::fuzz::ScratchDir dir;
  static const bool written = [] {
    avs::geometry::Mesh triangle;
    triangle.vertices = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}};
    triangle.triangles = {{0, 1, 2}};
    for (const std::string& name : avs::geometry::builtin_model_names()) {
      avs::geometry::save_ply(triangle, (dir.path() / (name + ".ply")).string());
    }
    avs::geometry::save_stl(triangle, (dir.path() / "part.stl").string());
    return true;
  }();
  (void)written;
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string dir = models().path().string();
  try {
    (void)avs::sim::parse_scene(avs::fuzz::text_of(data, size), "scene.yaml", dir, dir);
  } catch (const std::runtime_error& e) {
    avs::fuzz::expect_located(e, "scene.yaml");
  }
  return 0;
}
