// Where the sim components find scene files: absolute paths as they are; relative ones in the
// working directory, the source tree ($AVS_SOURCE_DIR) and its launch_config/scenes/, each
// also with ".yaml" appended. Shared by sim_scene and pattern_replay.
#pragma once

#include <string>

namespace avs::sim {

/// The path of scene `path`; throws std::runtime_error listing the places tried.
std::string resolve_scene_path(const std::string& path);

}  // namespace avs::sim
