// ProbeContainer: a one-component container of a bench's probe, run on a thread of its own in
// the bench's process, on the wall clock and a given DDS configuration and domain (`avs bench
// faults`, `avs bench soak`). RAII: it stops and joins on every way out, exceptions included.
// Header-only: only the benchmarks include it.
#pragma once

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "avs/runtime/container.hpp"
#include "avs/runtime/error.hpp"
#include "graph_loading.hpp"

namespace avs::cli {

template <class Probe>
class ProbeContainer {
 public:
  /// Writes the graph (`dir`/probe_graph.yaml, one component `probe` of `type`), starts it and
  /// waits (30 s at most) until the component exists. `who` prefixes the errors.
  ProbeContainer(const std::filesystem::path& dir, const std::string& type,
                 const std::string& cyclone_xml, int domain, const std::string& who) {
    const std::filesystem::path file = dir / "probe_graph.yaml";
    std::ofstream(file) << "# Written by " << who << ".\nclock: {source: wall}\ncontainers:\n"
                        << "  - name: probe\n    components:\n      - {type: " << type
                        << ", name: probe}\n";
    setenv("CYCLONEDDS_URI", cyclone_xml.c_str(), 1);
    graph_ = load_or_report(file.string(), {});
    if (!graph_) throw runtime::Error(who + ": the probe graph did not load");
    graph_->domain_id = domain;
    container_ = std::make_unique<runtime::Container>(*graph_, graph_->containers.at(0));
    runner_ = std::thread([this] { (void)container_->run(); });
    for (int i = 0; i < 3000 && probe_ == nullptr; ++i) {
      probe_ = dynamic_cast<const Probe*>(container_->find_component("probe"));
      if (probe_ == nullptr) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (probe_ == nullptr) {
      stop();
      throw runtime::Error(who + ": the probe did not start");
    }
  }
  ProbeContainer(const ProbeContainer&) = delete;
  ProbeContainer& operator=(const ProbeContainer&) = delete;
  ~ProbeContainer() { stop(); }

  const Probe& probe() const { return *probe_; }

  /// Stops the container and joins its thread (what the probe kept stays readable).
  void stop() {
    if (runner_.joinable()) {
      container_->stop();
      runner_.join();
    }
  }

 private:
  std::optional<graph::Graph> graph_;
  std::unique_ptr<runtime::Container> container_;
  std::thread runner_;
  const Probe* probe_ = nullptr;
};

}  // namespace avs::cli
