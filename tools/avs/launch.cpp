// avs launch FILE [NAME:=VALUE...]: starts each container of the graph as a child process
// (`avs container FILE --name C ...`), forwards Ctrl-C and SIGTERM, reports a container
// that dies with its exit status, applies each container's respawn policy, and returns
// non-zero if any container failed.
// With a deployment file (docs/deploy.md) and --host NAME it starts that host's containers
// with the Cyclone configuration generated for the host, and reports when a topic its
// containers read from other hosts loses its last publisher, and when one comes back.
#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <iostream>
#include <map>
#include <memory>
#include <set>

#include "avs/deploy/deployment.hpp"
#include "avs/deploy/publisher_watch.hpp"
#include "avs/deploy/roudi.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/process.hpp"
#include "commands.hpp"
#include "graph_loading.hpp"

extern char** environ;

namespace avs::cli {

namespace {

/// What to run for one container: the full command line and environment.
struct ChildPlan {
  std::vector<std::string> argv;
  std::vector<std::string> env;
};

struct Child {
  const graph::ContainerSpec* spec = nullptr;
  ChildPlan plan;
  pid_t pid = -1;
  int restarts = 0;
  double backoff_s = 0;
  double restart_at = -1;  // monotonic seconds; <0: none pending
  double started_at = 0;   // monotonic seconds of the last (re)start
  bool done = false;
  int status = 0;
};

double monotonic_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

pid_t spawn(const ChildPlan& plan, const sigset_t& original_mask) {
  // Everything the child needs is built before fork(): the launcher may have DDS threads.
  std::vector<std::string> argv_s = plan.argv;
  std::vector<std::string> env_s = plan.env;
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  const pid_t launcher = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    runtime::die_with_parent(launcher);
    sigprocmask(SIG_SETMASK, &original_mask, nullptr);
    execve("/proc/self/exe", argv.data(), envp.data());
    static const char msg[] = "avs launch: exec of /proc/self/exe failed\n";
    [[maybe_unused]] const auto n = write(2, msg, sizeof msg - 1);
    _exit(127);
  }
  return pid;
}

std::vector<std::string> current_environment() {
  std::vector<std::string> env;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) env.emplace_back(*e);
  return env;
}

/// `env` with NAME=value set (replacing an existing NAME).
void set_env(std::vector<std::string>& env, const std::string& name, const std::string& value) {
  const std::string prefix = name + "=";
  std::erase_if(env, [&](const std::string& e) { return e.rfind(prefix, 0) == 0; });
  env.push_back(prefix + value);
}

ChildPlan container_plan(const std::string& file, const std::string& container,
                         const std::vector<std::string>& words) {
  ChildPlan plan;
  plan.argv = {"avs", "container", file, "--name", container};
  plan.argv.insert(plan.argv.end(), words.begin(), words.end());
  plan.env = current_environment();
  return plan;
}

std::string describe_status(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + strsignal(WTERMSIG(status));
  return "stopped";
}

/// A container that ran this long before it ended gets a fresh restart budget and back-off.
constexpr double kStableRunS = 60.0;

/// Runs `children` until all ended (or Ctrl-C / SIGTERM); applies respawn policies.
int supervise(std::vector<Child>& children, const sigset_t& handled, const sigset_t& original) {
  std::map<pid_t, Child*> by_pid;
  for (auto& child : children) {
    child.pid = spawn(child.plan, original);
    child.started_at = monotonic_s();
    child.backoff_s = child.spec->respawn.backoff_s;
    by_pid[child.pid] = &child;
    std::cerr << "avs launch: started container '" << child.spec->name << "' (pid " << child.pid
              << ")\n";
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
      std::cerr << "avs launch: container '" << c.spec->name << "' " << describe_status(status)
                << "\n";
      using Kind = graph::RespawnPolicy::Kind;
      const auto& policy = c.spec->respawn;
      const bool respawn =
          !stopping && (policy.kind == Kind::always || (policy.kind == Kind::on_failure && failed));
      // A container that ran stably for a while failed anew, not again: fresh back-off and
      // restart budget (otherwise a process that fails once a day would run out of restarts).
      if (now - c.started_at >= kStableRunS) {
        c.restarts = 0;
        c.backoff_s = policy.backoff_s;
      }
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
        c.pid = spawn(c.plan, original);
        c.started_at = now;
        by_pid[c.pid] = &c;
        std::cerr << "avs launch: restarted container '" << c.spec->name << "' (pid " << c.pid
                  << ")\n";
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
  return result;
}

/// Blocks the signals the supervisor waits for; restores the mask when it ends.
struct SignalScope {
  sigset_t handled{}, original{};
  SignalScope() {
    sigemptyset(&handled);
    sigaddset(&handled, SIGINT);
    sigaddset(&handled, SIGTERM);
    sigaddset(&handled, SIGCHLD);
    sigprocmask(SIG_BLOCK, &handled, &original);
  }
  ~SignalScope() { sigprocmask(SIG_SETMASK, &original, nullptr); }
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;
};

int run_graph(const std::string& file, const std::vector<std::string>& words,
              const std::string& host) {
  auto g = load_or_report(file, words);
  if (!g) return 2;
  std::vector<Child> children;
  for (const auto& c : g->containers) {
    if (!host.empty() && !c.host.empty() && c.host != host) continue;
    children.push_back(Child{&c, container_plan(file, c.name, words)});
  }
  if (children.empty()) {
    std::cerr << "avs launch: no container to start" << (host.empty() ? "" : " on host " + host)
              << "\n";
    return 2;
  }
  SignalScope signals;
  return supervise(children, signals.handled, signals.original);
}

/// Topics read by `host`'s containers whose every publisher runs on another host: these are
/// the ones whose loss the launcher reports. topic (DDS name) -> "container 'x' on host 'A'".
std::map<std::string, std::string> remote_inputs(const deploy::Deployment& d,
                                                 const deploy::Host& host) {
  struct Ends {
    std::set<std::string> local_pub, remote_pub;
    bool read_here = false;
  };
  std::map<std::string, Ends> topics;
  const auto& registry = runtime::ComponentRegistry::instance();
  for (const auto& c : d.graph.containers) {
    const deploy::Host* h = d.host_of(c.name);
    const bool here = h == &host;
    for (const auto& comp : c.components) {
      const runtime::RegisteredComponent* reg = registry.find(comp.type);
      if (reg == nullptr) continue;
      for (const auto& p : reg->spec.publishes) {
        auto& e = topics["rt" + graph::port_topic(d.graph, comp, p)];
        (here ? e.local_pub : e.remote_pub)
            .insert("container '" + c.name + "' on host '" + (h ? h->name : "?") + "'");
      }
      if (here) {
        for (const auto& p : reg->spec.subscribes) {
          topics["rt" + graph::port_topic(d.graph, comp, p)].read_here = true;
        }
      }
    }
  }
  std::map<std::string, std::string> out;
  for (const auto& [topic, e] : topics) {
    if (!e.read_here || !e.local_pub.empty() || e.remote_pub.empty()) continue;
    std::string from;
    for (const auto& p : e.remote_pub) from += (from.empty() ? "" : ", ") + p;
    out[topic] = from;
  }
  return out;
}

/// "" when this machine can be `host` (its interface exists, its address is local), else why
/// not: starting with the wrong --host would send every container's traffic to the wrong place.
std::string host_mismatch(const deploy::Host& host) {
  if (host.interface.empty() && host.address.empty()) return "";
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return "";  // cannot tell; Cyclone will complain if wrong
  bool interface_found = host.interface.empty(), address_found = host.address.empty();
  std::string local;
  for (ifaddrs* a = list; a != nullptr; a = a->ifa_next) {
    if (a->ifa_name != nullptr && host.interface == a->ifa_name) interface_found = true;
    if (a->ifa_addr == nullptr || a->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN] = {};
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(a->ifa_addr)->sin_addr, text, sizeof text);
    local += std::string(local.empty() ? "" : ", ") + a->ifa_name + " " + text;
    if (host.address == text) address_found = true;
  }
  freeifaddrs(list);
  if (!interface_found) {
    return "host '" + host.name + "' uses interface '" + host.interface +
           "', which this machine does not have (it has: " + local + ")";
  }
  if (!address_found) {
    return "host '" + host.name + "' has address " + host.address +
           ", which no interface of this machine holds (it has: " + local + ")";
  }
  return "";
}

int run_deployment(const std::string& file, const std::vector<std::string>& words,
                   const std::string& host_name) {
  std::vector<std::string> rest;
  const auto overrides = graph::parse_arg_overrides(words, &rest);
  if (!rest.empty()) {
    std::cerr << "avs: unexpected argument '" << rest.front() << "' (arguments are NAME:=VALUE)\n";
    return 2;
  }
  deploy::LoadResult loaded = deploy::load_deployment(file, overrides);
  for (const auto& e : loaded.errors) std::cerr << e.str() << "\n";
  if (!loaded.ok()) return 2;
  const deploy::Deployment& d = *loaded.deployment;
  std::string hosts;
  for (const auto& h : d.host_names()) hosts += (hosts.empty() ? "'" : ", '") + h + "'";
  if (host_name.empty() && d.hosts.size() > 1) {
    std::cerr << "avs launch: " << file << " is a deployment over several hosts; say which one "
              << "this is with --host NAME (hosts: " << hosts << ")\n";
    return 2;
  }
  const deploy::Host* host = host_name.empty() ? &d.hosts.front() : d.find_host(host_name);
  if (host == nullptr) {
    std::cerr << "avs launch: " << file << " has no host '" << host_name << "' (hosts: " << hosts
              << ")\n";
    return 2;
  }
  if (const std::string why = host_mismatch(*host); !why.empty()) {
    std::cerr << "avs launch: wrong --host? " << why << "\n";
    return 2;
  }
  if (host->containers.empty()) {
    std::cerr << "avs launch: host '" << host->name << "' runs no container\n";
    return 2;
  }
  std::vector<std::string> graph_words;
  for (const auto& [k, v] : d.graph_args) graph_words.push_back(k + ":=" + v);
  std::vector<Child> children;
  for (const auto& name : host->containers) {
    Child child{d.graph.find_container(name), container_plan(d.graph_file, name, graph_words)};
    set_env(child.plan.env, "CYCLONEDDS_URI", deploy::cyclone_config(d, *host, name));
    set_env(child.plan.env, "AVS_DOMAIN_ID", std::to_string(d.domain_id));
    set_env(child.plan.env, "AVS_HOST", host->name);
    if (!d.partition.empty()) set_env(child.plan.env, "AVS_PARTITION", d.partition);
    children.push_back(std::move(child));
  }
  std::cerr << "avs launch: host '" << host->name << "' of " << file << ": domain " << d.domain_id
            << (d.partition.empty() ? "" : ", partition '" + d.partition + "'")
            << (d.discovery.multicast ? ", multicast discovery" : ", unicast peers")
            << (d.security.enabled ? ", DDS security on" : "") << "\n";

  SignalScope signals;  // before the watch's threads start, so they inherit the mask
  std::unique_ptr<deploy::Roudi> roudi;  // shared memory: RouDi before every participant
  if (d.shared_memory.enabled) {
    try {
      roudi = std::make_unique<deploy::Roudi>();
      std::cerr << "avs launch: shared memory through " << roudi->description() << "\n";
    } catch (const std::exception& e) {
      std::cerr << "avs launch: " << e.what() << "\n";
      return 2;
    }
  }
  const auto inputs = remote_inputs(d, *host);
  std::unique_ptr<deploy::PublisherWatch> watch;
  if (!inputs.empty()) {
    std::vector<std::string> topics;
    for (const auto& [t, from] : inputs) topics.push_back(t);
    const std::string prefix = "avs launch [" + host->name + "]: ";
    try {
      watch = std::make_unique<deploy::PublisherWatch>(
          d.domain_id, deploy::cyclone_config(d, *host, "observer"), topics,
          [prefix, inputs](const deploy::PublisherWatch::Event& e) {
            const std::string ros = e.topic.substr(2);
            if (e.lost) {
              std::cerr << prefix << "LOST publisher of " << ros << " (from " << inputs.at(e.topic)
                        << "): no live writer\n";
            } else {
              std::cerr << prefix << "publisher of " << ros << " alive (" << e.live_writers
                        << " writer(s))\n";
            }
          });
    } catch (const std::exception& e) {
      std::cerr << "avs launch: cannot watch remote publishers: " << e.what() << "\n";
    }
  }
  return supervise(children, signals.handled, signals.original);
}

int run_launch(const std::string& file, const std::vector<std::string>& words,
               const std::string& host) {
  if (deploy::is_deployment_file(file)) return run_deployment(file, words, host);
  return run_graph(file, words, host);
}

}  // namespace

int launch_graph(const std::string& file, const std::vector<std::string>& words,
                 const std::string& host) {
  return run_launch(file, words, host);
}

void add_launch_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "launch",
      "Start a YAML graph, or one host of a deployment (--host): a child process per container");
  static std::string file;
  static std::string host;
  static std::vector<std::string> words;
  cmd->add_option("file", file,
                  "graph YAML file (docs/graphs.md) or deployment YAML (docs/deploy.md)")
      ->required();
  cmd->add_option("args", words, "argument overrides NAME:=VALUE");
  cmd->add_option("--host", host,
                  "start only the containers placed on this host (required for a deployment "
                  "over several hosts)");
  cmd->callback([] { exit_status() = run_launch(file, words, host); });
}

}  // namespace avs::cli
