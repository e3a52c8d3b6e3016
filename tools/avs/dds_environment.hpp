// The DDS knobs a user sets in the shell, read by the command line and nowhere else:
// AVS_DOMAIN_ID (the domain of every participant a command creates) and AVS_PARTITION (the DDS
// partition of its readers and writers; `eval "$(avs deploy env FILE)"` exports both, and
// `avs launch` passes a deployment's to the containers it starts). Libraries and components take
// the domain and the partition from their caller: a graph or an option (issue 13 section 3).
#pragma once

#include <optional>
#include <string>

#include "avs/graph/graph.hpp"

namespace avs::cli {

/// $AVS_DOMAIN_ID when set and not empty; throws runtime::Error naming the variable when it is
/// not a domain id in [0, 232].
std::optional<int> environment_domain();

/// $AVS_DOMAIN_ID when set, else `fallback`: the default of every --domain option.
int domain_or_environment(int fallback);

/// $AVS_PARTITION, "" when unset.
std::string environment_partition();

class Command;
class Option;

/// The --domain option of a command: `domain` set to $AVS_DOMAIN_ID (or 0) as its default,
/// values in [0, 232].
Option* add_domain_option(Command* cmd, int& domain);

/// A loaded graph as the shell asks for it: its domain_id replaced by $AVS_DOMAIN_ID, its
/// partition set from $AVS_PARTITION.
void apply_environment(graph::Graph& g);

}  // namespace avs::cli
