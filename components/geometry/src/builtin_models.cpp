// Built-in models of section 7.2 (sizes in builtin_models.hpp).
#include "avs/geometry/builtin_models.hpp"
#include <cstdlib>
#include <stdexcept>

#include "avs/geometry/kendama.hpp"
#include "avs/geometry/primitives.hpp"

namespace avs::geometry {

std::vector<std::string> builtin_model_names() {
  return {"ken", "cube", "cylinder"};
}

Mesh make_builtin_model(const std::string& name) {
  if (name == "ken") return make_ken();
  if (name == "cube") return make_box(Eigen::Vector3d::Constant(0.100));
  if (name == "cylinder") return make_cylinder(0.040, 0.120, 64);
  throw std::invalid_argument("unknown built-in model '" + name + "' (ken, cube, cylinder)");
}

std::string default_models_dir() {
  if (const char* source = std::getenv("AVS_SOURCE_DIR"); source != nullptr && *source != 0) {
    return std::string(source) + "/models";
  }
  return AVS_GEOMETRY_MODELS_DIR;
}

}  // namespace avs::geometry
