#include "scene_path.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace avs::sim {

namespace {

namespace fs = std::filesystem;

/// The source tree (for relative scene paths): $AVS_SOURCE_DIR, else the configured one.
std::string source_dir() {
  if (const char* s = std::getenv("AVS_SOURCE_DIR"); s != nullptr && *s != 0) return s;
  return AVS_SIM_SOURCE_DIR;
}

}  // namespace

std::string resolve_scene_path(const std::string& path) {
  if (fs::path(path).is_absolute()) {
    if (!fs::exists(path)) throw std::runtime_error("scene file '" + path + "' does not exist");
    return path;
  }
  const std::string src = source_dir();
  std::vector<std::string> tried;
  for (const std::string& base : {std::string("."), src, src + "/launch_config/scenes"}) {
    for (const std::string& suffix : {std::string(), std::string(".yaml")}) {
      const fs::path candidate = fs::path(base) / (path + suffix);
      if (fs::is_regular_file(candidate)) return candidate.lexically_normal().string();
      tried.push_back(candidate.string());
    }
  }
  std::string list;
  for (const std::string& t : tried) list += (list.empty() ? "" : ", ") + t;
  throw std::runtime_error("scene '" + path + "' not found (tried " + list + ")");
}

}  // namespace avs::sim
