#include "avs/runtime/realtime.hpp"

#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace avs::runtime {

namespace {

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

}  // namespace

std::vector<pid_t> process_threads() {
  std::vector<pid_t> tids;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    tids.push_back(static_cast<pid_t>(std::stol(entry.path().filename().string())));
  }
  return tids;
}

RealtimeScope::RealtimeScope(const graph::RealtimeSpec& spec) {
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
      int failures = 0;
      for (Saved& s : saved_) {
        if (sched_setaffinity(s.tid, sizeof wanted, &wanted) == 0) {
          s.cpus_set = true;
        } else {
          ++failures;
        }
      }
      if (failures > 0) {
        refused_.push_back("realtime 'cpus' " + cpu_list(spec.cpus) + ": refused for " +
                           std::to_string(failures) + " thread(s) (" + std::strerror(errno) + ")");
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
      } else {
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
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
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
  for (const Saved& s : saved_) {
    if (s.policy_set) sched_setscheduler(s.tid, s.policy, &s.param);
    if (s.cpus_set) sched_setaffinity(s.tid, sizeof s.cpus, &s.cpus);
  }
}

}  // namespace avs::runtime
