// One container run in sim-time lockstep for a graph-level test: the components given as YAML
// flow maps, this process's own DDS domain (test_domain.hpp), the container run to the end of
// `duration_s` of simulated time. The one copy of what the decode, matching and sim graph tests
// each used to write for themselves.
#pragma once

#include <memory>
#include <string>
#include <thread>
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

enum class TestClock { lockstep, wall };

/// The same container run on a thread of its own, so that the test acts on it while it runs
/// (another process changing a parameter, say). stop() (or the destructor) ends it; read the
/// components' state only after stop(). Lockstep runs as fast as the machine does: a graph
/// with little work to do reaches `duration_s` at once; TestClock::wall runs it in wall time.
class BackgroundContainer {
 public:
  BackgroundContainer(const std::vector<std::string>& components, double duration_s,
                      TestClock clock = TestClock::lockstep, int domain = -1);
  ~BackgroundContainer();
  BackgroundContainer(const BackgroundContainer&) = delete;
  BackgroundContainer& operator=(const BackgroundContainer&) = delete;

  /// The graph and container (container null when the graph did not load: see load_errors).
  const ContainerRun& run() const { return run_; }
  /// Stops the container and waits for it; its run() status.
  int stop();

 private:
  ContainerRun run_;
  std::thread thread_;
};

}  // namespace avs::testing
