// A container's real-time settings (issue 16 section 3): scheduling policy and priority, CPU
// affinity and memory locking, applied to every thread of the process while the container
// runs. A setting the process may not make (no CAP_SYS_NICE, no memlock limit, a CPU it may not
// use) is one line saying so and the container runs without it: never a silent fallback, never
// a failure to start.
#pragma once

#include <sys/types.h>
#include <string>
#include <vector>

#include <sched.h>

#include "avs/graph/graph.hpp"

namespace avs::runtime {

class RealtimeScope {
 public:
  /// Applies `spec` to every thread of this process; threads the calling thread starts later
  /// inherit the policy and the affinity (Linux's defaults for new threads).
  explicit RealtimeScope(const graph::RealtimeSpec& spec);
  /// Puts back each thread's policy and affinity as they were (threads still alive; threads
  /// started meanwhile get the creating thread's old ones), unlocks.
  ~RealtimeScope();
  RealtimeScope(const RealtimeScope&) = delete;
  RealtimeScope& operator=(const RealtimeScope&) = delete;

  /// What was applied, one line ("SCHED_FIFO priority 80, CPUs 2,3, memory locked, 7 threads"),
  /// empty when nothing was asked for or nothing could be applied.
  const std::string& applied() const { return applied_; }
  /// One line per setting that was refused, with the reason and what runs instead.
  const std::vector<std::string>& refused() const { return refused_; }

 private:
  struct Saved {
    pid_t tid;
    int policy;
    sched_param param;
    cpu_set_t cpus;
    bool policy_set = false;
    bool cpus_set = false;
  };
  pid_t creator_;  ///< the thread that applied the settings (its old ones go to later threads)
  std::vector<Saved> saved_;
  bool any_policy_set_ = false;
  bool any_cpus_set_ = false;
  bool locked_ = false;
  std::string applied_;
  std::vector<std::string> refused_;
};

/// Thread ids of this process (/proc/self/task).
std::vector<pid_t> process_threads();

}  // namespace avs::runtime
