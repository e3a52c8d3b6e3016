// Issue 16 section 3: a container's `realtime:` settings (scheduling policy and priority, CPU
// affinity, memory locking) reach every thread of its process while it runs and are undone
// when it stops; a setting the process may not make is one line and the container runs without
// it. Whether SCHED_FIFO and mlockall are permitted depends on the machine (root or
// CAP_SYS_NICE / CAP_IPC_LOCK): the test checks whichever of the two outcomes the container
// reported, completely. A CPU the machine does not have is refused everywhere.
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "avs/graph/graph.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/realtime.hpp"
#include "avs/testing/test_domain.hpp"

namespace avs {
namespace {

struct Observed {
  int fifo_threads = 0;       ///< threads of the process with SCHED_FIFO while it ran
  int pinned_threads = 0;     ///< threads whose affinity was exactly {allowed_cpu()}
  long locked_kib = -1;       ///< VmLck while it ran
  std::string log;
  int status = -1;
};

/// The last CPU this process may use: the one the settings pin to (CPU 0 may be outside a
/// cpuset).
int allowed_cpu() {
  cpu_set_t set;
  sched_getaffinity(0, sizeof set, &set);
  int last = 0;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &set)) last = c;
  }
  return last;
}

int pinned_threads() {
  int n = 0;
  for (pid_t tid : runtime::process_threads()) {
    cpu_set_t set;
    if (sched_getaffinity(tid, sizeof set, &set) == 0 && CPU_COUNT(&set) == 1 &&
        CPU_ISSET(allowed_cpu(), &set)) {
      ++n;
    }
  }
  return n;
}

long vm_locked_kib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmLck:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

/// A talker and a listener on two lanes, wall clock, 1.5 s, with `realtime` as the container's
/// setting; the process's threads looked at once the settings reached them (or after 1 s, when
/// nothing was pinned).
Observed run_with(const std::string& realtime) {
  const auto file = std::filesystem::temp_directory_path() /
                    ("avs_realtime_" + std::to_string(getpid()) + ".yaml");
  {
    std::ofstream out(file);
    out << "domain_id: " << testing::test_domain() << "\n"
        << "clock: {source: wall, duration_s: 1.5}\n"
        << "containers:\n  - name: c\n    executor: thread_per_component\n"
        << "    realtime: " << realtime << "\n    components:\n"
        << "      - {type: test_talker, name: talker, parameters: {rate_hz: 100}}\n"
        << "      - {type: test_listener, name: listener}\n";
  }
  graph::LoadResult loaded = graph::load_graph(file.string(), {});
  std::filesystem::remove(file);
  Observed o;
  EXPECT_TRUE(loaded.ok());
  if (!loaded.ok()) return o;
  ::testing::internal::CaptureStderr();
  {
    runtime::Container container(*loaded.graph, loaded.graph->containers.front());
    std::thread run([&] { o.status = container.run(); });
    // The settings are applied once the components are constructed, which a loaded machine or a
    // sanitizer build makes slow: wait for the pinning (affinity comes first), then a little.
    for (int i = 0; i < 100 && pinned_threads() <= 3; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    o.pinned_threads = pinned_threads();
    for (pid_t tid : runtime::process_threads()) {
      if (sched_getscheduler(tid) == SCHED_FIFO) ++o.fifo_threads;
    }
    o.locked_kib = vm_locked_kib();
    run.join();
  }
  o.log = ::testing::internal::GetCapturedStderr();
  // What the container said about its settings, for whoever reads the test's output.
  std::istringstream lines(o.log);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("real") != std::string::npos) std::printf("%s\n", line.c_str());
  }
  return o;
}

TEST(RealtimeSettings, ReachEveryThreadWhileRunningAndAreUndoneAfter) {
  cpu_set_t before;
  ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // A sanitizer's shadow memory is terabytes of reserved address space: mlockall would try to
  // lock it all. Memory locking is left out of the instrumented build's run.
  const bool lock = false;
#else
  const bool lock = true;
#endif
  std::ostringstream settings;
  settings << "{sched: fifo, priority: 5, cpus: [" << allowed_cpu()
           << "], lock_memory: " << (lock ? "true" : "false") << "}";
  const Observed o = run_with(settings.str());
  EXPECT_EQ(o.status, 0) << o.log;
  // The affinity needs no privilege: applied to every thread (2 lanes, the DDS reader, the
  // test's own thread and Cyclone's: more than 3).
  EXPECT_GT(o.pinned_threads, 3) << o.log;
  if (o.log.find("real-time settings: SCHED_FIFO priority 5") != std::string::npos) {
    EXPECT_GT(o.fifo_threads, 3) << o.log;
  } else {
    EXPECT_NE(o.log.find("realtime 'sched': SCHED_FIFO priority 5 not permitted"),
              std::string::npos)
        << o.log;
    EXPECT_EQ(o.fifo_threads, 0) << "refused: no thread half-way real-time";
  }
  if (!lock) {
    EXPECT_EQ(o.log.find("memory locked"), std::string::npos) << o.log;
  } else if (o.log.find("memory locked") != std::string::npos) {
    EXPECT_GT(o.locked_kib, 0);
  } else {
    EXPECT_NE(o.log.find("realtime 'lock_memory': mlockall refused"), std::string::npos) << o.log;
  }
  // Undone: this thread is SCHED_OTHER on its old CPUs again, nothing locked.
  EXPECT_EQ(sched_getscheduler(0), SCHED_OTHER);
  cpu_set_t after;
  ASSERT_EQ(sched_getaffinity(0, sizeof after, &after), 0);
  EXPECT_TRUE(CPU_EQUAL(&before, &after));
  EXPECT_EQ(vm_locked_kib(), 0);
}

TEST(RealtimeSettings, ACpuTheMachineLacksIsOneLineAndTheContainerRunsWithoutIt) {
  const Observed o = run_with("{cpus: [1023]}");
  EXPECT_EQ(o.status, 0) << o.log;
  EXPECT_NE(o.log.find("realtime 'cpus' 1023: CPU 1023 not available to this process (it may "
                       "use "),
            std::string::npos)
      << o.log;
  EXPECT_NE(o.log.find("running on all of them"), std::string::npos) << o.log;
  EXPECT_EQ(o.log.find("real-time settings:"), std::string::npos) << "nothing applied" << o.log;
  EXPECT_EQ(o.fifo_threads, 0);
}

}  // namespace
}  // namespace avs
