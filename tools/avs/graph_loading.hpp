// Loading a graph for a command: errors printed one per line, nullopt on any error.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "avs/graph/graph.hpp"

namespace avs::cli {

std::optional<graph::Graph> load_or_report(const std::string& file,
                                           const std::vector<std::string>& words);

}  // namespace avs::cli
