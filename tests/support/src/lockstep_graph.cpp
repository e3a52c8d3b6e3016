#include "avs/testing/lockstep_graph.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "avs/testing/test_domain.hpp"

namespace avs::testing {

namespace {

ContainerRun run_container(const std::vector<std::string>& components, const std::string& clock,
                           int domain) {
  if (domain < 0) domain = test_domain();
  const auto file = std::filesystem::temp_directory_path() /
                    ("avs_lockstep_" + std::to_string(getpid()) + "_" + std::to_string(domain) +
                     ".yaml");
  {
    std::ofstream out(file);
    out << "domain_id: " << domain << "\n"
        << "clock: " << clock << "\n"
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
  run.status = run.container->run();
  return run;
}

}  // namespace

ContainerRun run_lockstep_container(const std::vector<std::string>& components, double duration_s,
                                    int domain) {
  return run_container(
      components, "{source: sim, mode: lockstep, duration_s: " + std::to_string(duration_s) + "}",
      domain);
}

ContainerRun run_wall_clock_container(const std::vector<std::string>& components, double duration_s,
                                      int domain) {
  return run_container(components, "{source: wall, duration_s: " + std::to_string(duration_s) + "}",
                       domain);
}

}  // namespace avs::testing
