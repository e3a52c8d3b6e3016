#include "avs/runtime/realtime.hpp"

#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace avs::runtime {

namespace {

constexpr int CAP_IPC_LOCK_BIT = 14;  ///< linux/capability.h's CAP_IPC_LOCK

const char* policy_name(graph::RealtimeSpec::Policy p) {
  switch (p) {
    case graph::RealtimeSpec::Policy::fifo:
      return "SCHED_FIFO";
    case graph::RealtimeSpec::Policy::rr:
      return "SCHED_RR";
    case graph::RealtimeSpec::Policy::other:
      break;
  }
  return "SCHED_OTHER";
}

int policy_value(graph::RealtimeSpec::Policy p) {
  switch (p) {
    case graph::RealtimeSpec::Policy::fifo:
      return SCHED_FIFO;
    case graph::RealtimeSpec::Policy::rr:
      return SCHED_RR;
    case graph::RealtimeSpec::Policy::other:
      break;
  }
  return SCHED_OTHER;
}

std::string cpu_list(const std::vector<int>& cpus) {
  std::string out;
  for (int c : cpus) {
    if (!out.empty()) out += ',';
    out += std::to_string(c);
  }
  return out;
}

std::string cpu_list(const cpu_set_t& set) {
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  }
  return cpu_list(cpus);
}

/// CAP_IPC_LOCK (bit 14) in the effective set (/proc/self/status CapEff).
bool has_ipc_lock() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("CapEff:", 0) == 0) {
      return (std::stoull(line.substr(7), nullptr, 16) >> CAP_IPC_LOCK_BIT) & 1U;
    }
  }
  return false;
}

bool thread_of_this_process(pid_t tid) {
  std::error_code ec;
  return std::filesystem::exists("/proc/self/task/" + std::to_string(tid), ec);
}

}  // namespace

std::vector<pid_t> process_threads() {
  std::vector<pid_t> tids;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    tids.push_back(static_cast<pid_t>(std::stol(entry.path().filename().string())));
  }
  return tids;
}

RealtimeScope::RealtimeScope(const graph::RealtimeSpec& spec) : creator_(gettid()) {
  if (!spec.any()) return;
  for (pid_t tid : process_threads()) {
    Saved s{tid, sched_getscheduler(tid), {}, {}};
    if (s.policy < 0 || sched_getparam(tid, &s.param) != 0 ||
        sched_getaffinity(tid, sizeof s.cpus, &s.cpus) != 0) {
      continue;  // the thread ended meanwhile
    }
    saved_.push_back(s);
  }
  std::vector<std::string> done;

  if (!spec.cpus.empty()) {
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    sched_getaffinity(0, sizeof allowed, &allowed);
    std::vector<int> missing;
    cpu_set_t wanted;
    CPU_ZERO(&wanted);
    for (int c : spec.cpus) {
      if (c >= CPU_SETSIZE || !CPU_ISSET(c, &allowed)) missing.push_back(c);
      if (c < CPU_SETSIZE) CPU_SET(c, &wanted);
    }
    if (!missing.empty()) {
      refused_.push_back("realtime 'cpus' " + cpu_list(spec.cpus) + ": CPU " + cpu_list(missing) +
                         " not available to this process (it may use " + cpu_list(allowed) +
                         "); running on all of them");
    } else {
      int failures = 0, err = 0;
      for (Saved& s : saved_) {
        if (sched_setaffinity(s.tid, sizeof wanted, &wanted) == 0) {
          s.cpus_set = true;
        } else if (errno != ESRCH) {  // ESRCH: the thread ended meanwhile
          ++failures;
          err = errno;
        }
      }
      if (failures > 0) {
        refused_.push_back("realtime 'cpus' " + cpu_list(spec.cpus) + ": refused for " +
                           std::to_string(failures) + " thread(s) (" + std::strerror(err) + ")");
      }
      done.push_back("CPUs " + cpu_list(spec.cpus));
    }
  }

  if (spec.policy != graph::RealtimeSpec::Policy::other) {
    sched_param param{};
    param.sched_priority = spec.priority;
    int err = 0;
    for (Saved& s : saved_) {
      if (sched_setscheduler(s.tid, policy_value(spec.policy), &param) == 0) {
        s.policy_set = true;
      } else if (errno != ESRCH) {  // ESRCH: the thread ended meanwhile
        err = errno;
      }
    }
    const std::string what =
        std::string(policy_name(spec.policy)) + " priority " + std::to_string(spec.priority);
    if (err != 0) {
      // Put back the threads that did change: all of them real-time or none.
      for (Saved& s : saved_) {
        if (s.policy_set) sched_setscheduler(s.tid, s.policy, &s.param);
        s.policy_set = false;
      }
      refused_.push_back("realtime 'sched': " + what + " not permitted (" + std::strerror(err) +
                         (err == EPERM ? ": needs CAP_SYS_NICE or an rtprio limit in "
                                         "/etc/security/limits.conf"
                                       : "") +
                         "); running with SCHED_OTHER");
    } else {
      done.insert(done.begin(), what);
    }
  }

  if (spec.lock_memory) {
    rlimit limit{};
    getrlimit(RLIMIT_MEMLOCK, &limit);
    if (limit.rlim_cur != RLIM_INFINITY && !has_ipc_lock()) {
      // mlockall(MCL_FUTURE) would succeed now and make every later allocation past the limit
      // fail (a lane that cannot start, a bad_alloc mid-frame): refused before it can.
      refused_.push_back("realtime 'lock_memory': the memlock limit is " +
                         std::to_string(limit.rlim_cur / 1024) +
                         " KiB (ulimit -l) and the process lacks CAP_IPC_LOCK: locking all future "
                         "memory would make allocations past it fail; running unlocked");
    } else if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      locked_ = true;
      done.push_back("memory locked");
    } else {
      const int err = errno;
      refused_.push_back(std::string("realtime 'lock_memory': mlockall refused (") +
                         std::strerror(err) +
                         (err == EPERM || err == ENOMEM
                              ? ": needs CAP_IPC_LOCK or a memlock limit (ulimit -l) as large as "
                                "the process"
                              : "") +
                         "); running unlocked");
    }
  }

  for (const Saved& s : saved_) {
    any_policy_set_ = any_policy_set_ || s.policy_set;
    any_cpus_set_ = any_cpus_set_ || s.cpus_set;
  }
  if (!done.empty()) {
    for (const auto& d : done) {
      if (!applied_.empty()) applied_ += ", ";
      applied_ += d;
    }
    applied_ += " on " + std::to_string(saved_.size()) + " thread(s)";
  }
}

RealtimeScope::~RealtimeScope() {
  if (locked_) munlockall();
  // A thread id of a thread that ended may belong to another process by now: only this
  // process's threads are touched. Threads started while the scope held (a component's own,
  // started on activation) inherited its settings and get those the creating thread had.
  const Saved* caller = nullptr;
  for (const Saved& s : saved_) {
    if (s.tid == creator_) caller = &s;
  }
  for (pid_t tid : process_threads()) {
    const Saved* found = nullptr;
    for (const Saved& s : saved_) {
      if (s.tid == tid) found = &s;
    }
    const Saved* put_back = found != nullptr ? found : caller;
    if (put_back == nullptr || !thread_of_this_process(tid)) continue;
    const bool policy = found != nullptr ? found->policy_set : any_policy_set_;
    const bool cpus = found != nullptr ? found->cpus_set : any_cpus_set_;
    if (policy) sched_setscheduler(tid, put_back->policy, &put_back->param);
    if (cpus) sched_setaffinity(tid, sizeof put_back->cpus, &put_back->cpus);
  }
}

}  // namespace avs::runtime
