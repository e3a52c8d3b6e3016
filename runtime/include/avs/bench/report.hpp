// The one shape every `avs bench NAME` shares: rows with ours beside a peer measured in
// the same run and their ratio; `--json` prints `json` (keys carry units, e.g.
// "avs_update_ms", "speedup_vs_opencv") as one object. Benchmarks register themselves
// with AVS_REGISTER_BENCH in a component library.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace avs::bench {

struct Row {
  std::string what;       ///< "rolling update + triangulation, 512x512"
  std::string unit;       ///< "ms"
  double ours = 0;        ///< median
  std::string peer_name;  ///< "OpenCV 4.6 GrayCodePattern", empty when no peer
  double peer = 0;        ///< median of the peer, same inputs, same run
};

struct Report {
  std::string title;
  std::vector<Row> rows;
  std::map<std::string, double> json;  ///< stable keys with units
  std::vector<std::string> notes;      ///< printed under the table
};

/// args: the words after `avs bench NAME` (e.g. "--model", "ken.ply"); `--json` is handled
/// by the caller.
using BenchFunction = std::function<Report(const std::vector<std::string>& args)>;

struct RegisteredBench {
  std::string name;
  std::string description;
  BenchFunction run;
};

std::vector<RegisteredBench>& bench_registry();

inline bool register_bench(std::string name, std::string description, BenchFunction run) {
  bench_registry().push_back({std::move(name), std::move(description), std::move(run)});
  return true;
}

}  // namespace avs::bench

#define AVS_REGISTER_BENCH(ident, name, description, fn) \
  [[maybe_unused]] static const bool avs_bench_registered_##ident = \
      ::avs::bench::register_bench(name, description, fn)
