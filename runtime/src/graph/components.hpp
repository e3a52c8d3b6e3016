// Internal to the graph loader: reading one component entry.
#pragma once

#include <optional>

#include "load_state.hpp"

namespace avs::graph::detail {

/// Reads and checks one entry of a container's `components:` list against the
/// registered spec of its type (it runs in `container`); adds its topic endpoints to `state`.
/// nullopt on errors (all reported).
std::optional<ComponentInstance> read_component(LoadState& state, const FileReader& reader,
                                                const YAML::Node& node,
                                                const std::string& container);

}  // namespace avs::graph::detail
