// The objects of the paper's experiments (section 7.2), generated here and shipped as
// binary PLY files in models/ (regenerate with the avs_make_models program).
#pragma once

#include <string>
#include <vector>

#include "avs/geometry/mesh.hpp"

namespace avs::geometry {

/// Names of the built-in models: "ken", "cube", "cylinder".
std::vector<std::string> builtin_model_names();

/// Builds a built-in model, in its object frame:
/// - "ken": kendama ken, 180 mm long, frame as in kendama.hpp;
/// - "cube": 100 mm cube (section 7.2.2), centred at the origin, faces normal to the axes;
/// - "cylinder": diameter 80 mm, height 120 mm (section 7.2.3 gives no size; our choice),
///   axis along Z, centred at the origin.
/// Throws std::invalid_argument for an unknown name.
Mesh make_builtin_model(const std::string& name);

/// The folder the shipped models/*.ply are read from: $AVS_SOURCE_DIR/models when that is set,
/// else the source tree's models/ (the one lookup every component and tool uses).
std::string default_models_dir();

}  // namespace avs::geometry
