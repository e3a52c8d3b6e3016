// Load for tests whose result must not depend on it: threads that keep cores busy for as long
// as the object lives (a lockstep graph must give the same result beside them).
#pragma once

#include <atomic>
#include <thread>
#include <vector>

namespace avs::testing {

class CpuHog {
 public:
  /// `threads` busy threads (default: one per core).
  explicit CpuHog(unsigned threads = std::thread::hardware_concurrency()) {
    for (unsigned i = 0; i < (threads == 0 ? 1 : threads); ++i) {
      threads_.emplace_back([this] {
        volatile unsigned long spins = 0;
        while (!stop_.load(std::memory_order_relaxed)) spins = spins + 1;
      });
    }
  }
  ~CpuHog() {
    stop_ = true;
    for (auto& t : threads_) t.join();
  }
  CpuHog(const CpuHog&) = delete;
  CpuHog& operator=(const CpuHog&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

}  // namespace avs::testing
