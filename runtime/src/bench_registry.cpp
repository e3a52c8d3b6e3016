#include "avs/bench/report.hpp"

namespace avs::bench {

std::vector<RegisteredBench>& bench_registry() {
  static std::vector<RegisteredBench> registry;
  return registry;
}

}  // namespace avs::bench
