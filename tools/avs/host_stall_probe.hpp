// A thread that asks to wake every millisecond (absolute deadlines, steady clock) and records
// each wake-up more than a threshold late: what the machine does to an ordinary thread on it
// (SCHED_OTHER, like the graph's). On the 2-core microVM this project runs on, such a sleeper on
// an otherwise idle machine was woken up to 18 ms late, in bursts every two minutes
// (docs/reliability.md, "Soak"): a loss counter that rises during such a stall, or a latency
// maximum, is then a figure of the host, and the benches print the stalls beside them. On a
// loaded machine it also counts the contention for the cores. About a thousand short wake-ups a
// second.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avs/runtime/log_clock.hpp"

namespace avs::cli {

class HostStallProbe {
 public:
  struct Stall {
    double t_s;        ///< since the probe started
    double late_ms;    ///< how much later than asked the thread ran
    std::string wall;  ///< local wall-clock time (HH:MM:SS.mmm), to match log lines
  };

  explicit HostStallProbe(double threshold_ms = 3.0)
      : threshold_ms_(threshold_ms), start_(std::chrono::steady_clock::now()) {
    thread_ = std::thread([this] { run(); });
  }
  ~HostStallProbe() {
    stop_ = true;
    thread_.join();
  }
  HostStallProbe(const HostStallProbe&) = delete;
  HostStallProbe& operator=(const HostStallProbe&) = delete;

  /// The stalls so far, oldest first.
  std::vector<Stall> stalls() const {
    std::lock_guard lock(mutex_);
    return stalls_;
  }
  /// Stalls from `from_s` on (probe time): their count and the longest (ms, 0 when none).
  std::pair<int, double> since(double from_s) const {
    std::lock_guard lock(mutex_);
    int n = 0;
    double longest = 0;
    for (const Stall& s : stalls_) {
      if (s.t_s < from_s) continue;
      ++n;
      longest = std::max(longest, s.late_ms);
    }
    return {n, longest};
  }
  /// Writes t_s,wall,late_ms per stall.
  void write_csv(const std::string& path) const {
    std::ofstream out(path);
    out << "t_s,wall,late_ms\n";
    for (const Stall& s : stalls()) out << s.t_s << "," << s.wall << "," << s.late_ms << "\n";
  }

 private:
  void run() {
    using Clock = std::chrono::steady_clock;
    auto next = Clock::now();
    while (!stop_) {
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
      const auto now = Clock::now();
      const double late_ms = std::chrono::duration<double, std::milli>(now - next).count();
      if (late_ms <= threshold_ms_) continue;
      const std::string wall = runtime::log_clock_text(std::chrono::system_clock::now());
      {
        std::lock_guard lock(mutex_);
        // Bounded: a week-long soak on a bad host keeps its first 100,000 stalls.
        if (stalls_.size() < 100000) {
          stalls_.push_back({std::chrono::duration<double>(now - start_).count(), late_ms, wall});
        }
      }
      next = now;  // one stall is one record, not a burst of catch-up wake-ups
    }
  }

  double threshold_ms_;
  std::chrono::steady_clock::time_point start_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::vector<Stall> stalls_;
  std::thread thread_;
};

}  // namespace avs::cli
