// One container run in sim-time lockstep for a graph-level test: the components given as YAML
// flow maps, this process's own DDS domain (test_domain.hpp), the container run to the end of
// `duration_s` of simulated time. The one copy of what the decode, matching and sim graph tests
// each used to write for themselves.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "avs/graph/graph.hpp"
#include "avs/runtime/container.hpp"

namespace avs::testing {

struct ContainerRun {
  std::unique_ptr<graph::Graph> graph;
  std::unique_ptr<runtime::Container> container;
  int status = -1;  ///< Container::run()'s; -1 when the graph did not load
  std::vector<std::string> load_errors;

  /// The component `name` as a T (nullptr when absent or of another type).
  template <class T>
  T* find(const std::string& name) const {
    return container ? dynamic_cast<T*>(container->find_component(name)) : nullptr;
  }
};

/// Runs one single-threaded lockstep container holding `components` ("{type: decode, name:
/// decode, parameters: {...}}", one per element) for `duration_s` of simulated time on
/// `domain` (default: this process's test domain).
ContainerRun run_lockstep_container(const std::vector<std::string>& components, double duration_s,
                                    int domain = -1);

/// The same on the wall clock, for `duration_s` of real time (components that talk to devices
/// on their own threads, e.g. camera + sim_camera). Never assert speed with it.
ContainerRun run_wall_clock_container(const std::vector<std::string>& components, double duration_s,
                                      int domain = -1);

}  // namespace avs::testing
