// Adapter: scenes and simulator settings from YAML (format in docs/sim.md). Errors throw
// std::runtime_error naming the file, line and column.
#pragma once

#include <string>

#include "avs/sim/scene.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {

struct SceneFile {
  Scene scene;
  SimulatorConfig config;  ///< defaults overridden by the file's `sensor:` and `head:` maps
};

/// Parses YAML text. Mesh paths are relative to `base_dir`; built-in models come from
/// `models_dir` (empty: the source tree's models/, or $AVS_SOURCE_DIR/models if set).
SceneFile parse_scene(const std::string& yaml_text, const std::string& name_for_errors,
                      const std::string& base_dir = ".", const std::string& models_dir = "");

/// Reads and parses a scene file; meshes relative to the file's directory.
SceneFile load_scene(const std::string& path, const std::string& models_dir = "");

}  // namespace avs::sim
