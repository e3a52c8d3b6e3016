#include "avs/testing/lockstep_graph.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "avs/testing/test_domain.hpp"

namespace avs::testing {

namespace {

/// The graph of run_lockstep_container (or in wall time) loaded and its container made, not run.
ContainerRun load_container(const std::vector<std::string>& components, double duration_s,
                            TestClock clock, int domain) {
  if (domain < 0) domain = test_domain();
  const auto file = std::filesystem::temp_directory_path() /
                    ("avs_lockstep_" + std::to_string(getpid()) + "_" + std::to_string(domain) +
                     ".yaml");
  {
    std::ofstream out(file);
    out << "domain_id: " << domain << "\n"
        << (clock == TestClock::lockstep ? "clock: {source: sim, mode: lockstep, duration_s: "
                                         : "clock: {source: wall, duration_s: ")
        << duration_s << "}\n"
        << "containers:\n"
        << "  - name: test\n"
        << "    executor: single_threaded\n"
        << "    components:\n";
    for (const auto& c : components) out << "      - " << c << "\n";
  }
  graph::LoadResult loaded = graph::load_graph(file.string(), {});
  std::filesystem::remove(file);
  ContainerRun run;
  for (const auto& e : loaded.errors) run.load_errors.push_back(e.str());
  if (!loaded.ok()) return run;
  run.graph = std::make_unique<graph::Graph>(std::move(*loaded.graph));
  run.container = std::make_unique<runtime::Container>(*run.graph, run.graph->containers.front());
  return run;
}

}  // namespace

ContainerRun run_lockstep_container(const std::vector<std::string>& components, double duration_s,
                                    int domain) {
  ContainerRun run = load_container(components, duration_s, TestClock::lockstep, domain);
  if (run.container) run.status = run.container->run();
  return run;
}

ContainerRun run_wall_clock_container(const std::vector<std::string>& components, double duration_s,
                                      int domain) {
  ContainerRun run = load_container(components, duration_s, TestClock::wall, domain);
  if (run.container) run.status = run.container->run();
  return run;
}

BackgroundContainer::BackgroundContainer(const std::vector<std::string>& components,
                                         double duration_s, TestClock clock, int domain)
    : run_(load_container(components, duration_s, clock, domain)) {
  if (run_.container) thread_ = std::thread([this] { run_.status = run_.container->run(); });
}

BackgroundContainer::~BackgroundContainer() {
  stop();
}

int BackgroundContainer::stop() {
  if (thread_.joinable()) {
    run_.container->stop();
    thread_.join();
  }
  return run_.status;
}

}  // namespace avs::testing
