// avs launch FILE [NAME:=VALUE...]: starts each container of the graph as a child process
// (`avs container FILE --name C ...`), forwards Ctrl-C and SIGTERM, reports a container
// that dies with its exit status, applies each container's respawn policy, and returns
// non-zero if any container failed.
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "graph_loading.hpp"

namespace avs::cli {

namespace {

struct Child {
  const graph::ContainerSpec* spec = nullptr;
  pid_t pid = -1;
  int restarts = 0;
  double backoff_s = 0;
  double restart_at = -1;  // monotonic seconds; <0: none pending
  bool done = false;
  int status = 0;
};

double monotonic_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

pid_t spawn(const std::string& file, const std::string& container,
            const std::vector<std::string>& words, const sigset_t& original_mask) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    sigprocmask(SIG_SETMASK, &original_mask, nullptr);
    std::vector<std::string> argv_s = {"avs", "container", file, "--name", container};
    argv_s.insert(argv_s.end(), words.begin(), words.end());
    std::vector<char*> argv;
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    execv("/proc/self/exe", argv.data());
    std::cerr << "avs launch: exec failed: " << std::strerror(errno) << "\n";
    _exit(127);
  }
  return pid;
}

std::string describe_status(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + strsignal(WTERMSIG(status));
  return "stopped";
}

int run_launch(const std::string& file, const std::vector<std::string>& words,
               const std::string& host) {
  auto g = load_or_report(file, words);
  if (!g) return 2;

  sigset_t handled, original;
  sigemptyset(&handled);
  sigaddset(&handled, SIGINT);
  sigaddset(&handled, SIGTERM);
  sigaddset(&handled, SIGCHLD);
  sigprocmask(SIG_BLOCK, &handled, &original);

  std::map<pid_t, Child*> by_pid;
  std::vector<Child> children;
  for (const auto& c : g->containers) {
    if (!host.empty() && !c.host.empty() && c.host != host) continue;
    children.push_back(Child{&c});
  }
  if (children.empty()) {
    std::cerr << "avs launch: no container to start" << (host.empty() ? "" : " on host " + host) << "\n";
    return 2;
  }
  for (auto& child : children) {
    child.pid = spawn(file, child.spec->name, words, original);
    child.backoff_s = child.spec->respawn.backoff_s;
    by_pid[child.pid] = &child;
    std::cerr << "avs launch: started container '" << child.spec->name << "' (pid " << child.pid << ")\n";
  }

  bool stopping = false;
  double kill_at = -1;
  int result = 0;
  auto alive = [&] {
    for (const auto& c : children) {
      if (!c.done) return true;
    }
    return false;
  };
  while (alive()) {
    timespec timeout{0, 100'000'000};
    siginfo_t info{};
    const int sig = sigtimedwait(&handled, &info, &timeout);
    const double now = monotonic_s();
    if (sig == SIGINT || sig == SIGTERM) {
      if (!stopping) {
        std::cerr << "avs launch: " << strsignal(sig) << ", stopping containers\n";
        stopping = true;
        kill_at = now + 10.0;
        for (auto& c : children) {
          if (c.pid > 0) kill(c.pid, SIGTERM);
          if (c.restart_at >= 0) c.done = true, c.restart_at = -1;
        }
      }
    }
    // Reap every child that ended.
    for (;;) {
      int status = 0;
      const pid_t pid = waitpid(-1, &status, WNOHANG);
      if (pid <= 0) break;
      auto it = by_pid.find(pid);
      if (it == by_pid.end()) continue;
      Child& c = *it->second;
      by_pid.erase(it);
      c.pid = -1;
      const bool failed = !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
      std::cerr << "avs launch: container '" << c.spec->name << "' " << describe_status(status) << "\n";
      using Kind = graph::RespawnPolicy::Kind;
      const auto& policy = c.spec->respawn;
      const bool respawn = !stopping && (policy.kind == Kind::always ||
                                         (policy.kind == Kind::on_failure && failed));
      if (respawn && c.restarts < policy.max_restarts) {
        c.restart_at = now + c.backoff_s;
        std::cerr << "avs launch: restarting '" << c.spec->name << "' in " << c.backoff_s
                  << " s (restart " << c.restarts + 1 << " of " << policy.max_restarts << ")\n";
        c.backoff_s *= 2;
        continue;
      }
      if (respawn) std::cerr << "avs launch: '" << c.spec->name << "' reached its restart limit\n";
      c.done = true;
      c.status = status;
      if (failed && !(stopping && WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM)) result = 1;
    }
    for (auto& c : children) {
      if (c.restart_at >= 0 && now >= c.restart_at && !stopping) {
        c.restart_at = -1;
        ++c.restarts;
        c.pid = spawn(file, c.spec->name, words, original);
        by_pid[c.pid] = &c;
      }
    }
    if (stopping && kill_at >= 0 && now > kill_at) {
      for (auto& c : children) {
        if (c.pid > 0) {
          std::cerr << "avs launch: container '" << c.spec->name << "' did not stop, killing it\n";
          kill(c.pid, SIGKILL);
        }
      }
      kill_at = -1;
    }
  }
  sigprocmask(SIG_SETMASK, &original, nullptr);
  return result;
}

}  // namespace

int launch_graph(const std::string& file, const std::vector<std::string>& words,
                 const std::string& host) {
  return run_launch(file, words, host);
}

void add_launch_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("launch", "Start a YAML graph: one child process per container");
  static std::string file;
  static std::string host;
  static std::vector<std::string> words;
  cmd->add_option("file", file, "graph YAML file (see docs/graphs.md)")->required();
  cmd->add_option("args", words, "argument overrides NAME:=VALUE");
  cmd->add_option("--host", host, "start only the containers placed on this host");
  cmd->callback([] { exit_status() = run_launch(file, words, host); });
}

}  // namespace avs::cli
