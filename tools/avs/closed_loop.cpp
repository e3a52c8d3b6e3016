// The simulated closed loop in one process (see closed_loop.hpp).
#include "closed_loop.hpp"

#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "avs/run_recorder/run_recorder_component.hpp"
#include "avs/runtime/container.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "graph_loading.hpp"

namespace avs::cli {

namespace {

std::atomic<bool> g_run_interrupted{false};

std::string bool_word(bool b) {
  return b ? "true" : "false";
}

/// A bag_recorder instance (every parameter its default but these) for the loop's container.
graph::ComponentInstance bag_recorder(const ClosedLoopRun& run) {
  const auto* registered = runtime::ComponentRegistry::instance().find("bag_recorder");
  if (registered == nullptr) throw runtime::Error("this avs has no bag_recorder component");
  graph::ComponentInstance instance;
  instance.type = "bag_recorder";
  instance.name = "closed_loop_bag";
  for (const auto& p : registered->spec.parameters) {
    instance.parameters.set(p.name, p.default_value);
  }
  instance.parameters.set("file", std::filesystem::absolute(run.bag).string());
  instance.parameters.set("topics", run.bag_topics);
  instance.parameters.set("if_exists", std::string("overwrite"));
  instance.parameters.set("compression", std::string("lz4"));  // camera frames: speed over size
  instance.where.file = "(avs: the closed loop's bag, " + run.bag.string() + ")";
  return instance;
}

std::string progress_line(const runtime::Container& container,
                          const run_recorder::RecorderProgress* progress, double duration_s,
                          double wall_s) {
  const double sim_s = container.now().seconds();
  char buf[256];
  int n = std::snprintf(buf, sizeof buf, "sim %6.2f / %.2f s (%3.0f%%)", sim_s, duration_s,
                        duration_s > 0 ? 100.0 * sim_s / duration_s : 0.0);
  if (progress != nullptr && sim_s > 0) {
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n),
                       " | camera %4.0f Hz | depth %4.0f Hz | poses %4.0f Hz (sim time)",
                       static_cast<double>(progress->frames.load()) / sim_s,
                       static_cast<double>(progress->depth_updates.load()) / sim_s,
                       static_cast<double>(progress->poses.load()) / sim_s);
  }
  if (wall_s > 0) {
    const double remaining = sim_s > 0 ? (duration_s - sim_s) * wall_s / sim_s : 0.0;
    std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n),
                  " | %.2fx real time, ~%.0f s left", sim_s / wall_s, remaining);
  }
  return buf;
}

}  // namespace

bool interrupted_by_signal() {
  return g_run_interrupted.load();
}

std::filesystem::path closed_loop_graph() {
  return std::filesystem::path(AVS_SOURCE_DIR) / "launch_config" / "closed_loop.yaml";
}

int free_tcp_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket() failed while looking for a free port");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof addr;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
    close(fd);
    throw std::runtime_error("cannot bind a loopback port for the simulated amplifiers");
  }
  close(fd);
  return ntohs(addr.sin_port);
}

int choose_closed_loop_domain(const ClosedLoopRun& run, std::ostream& progress) {
  // The run is private unless asked otherwise: samples of another system on the same DDS
  // domain (a second demo, a test) would reach these components and break the lockstep
  // run's determinism. AVS_DOMAIN_ID=N shares the run with `avs topic` & co. on domain N.
  const auto given = environment_domain();
  const int domain = given ? *given : 200 + getpid() % 32;
  static bool said = false;
  if (!said) {
    // The one command that watches the run from a second shell, domain included.
    progress << "[" << run.scenario << "] DDS domain " << domain
             << (given ? " ($AVS_DOMAIN_ID)" : " (private to this run)")
             << "; watch it with: avs graph --domain " << domain << "  (or AVS_DOMAIN_ID=" << domain
             << " avs topic list, avs param list, ...)\n";
    said = true;
  }
  return domain;
}

ClosedLoopOutcome run_closed_loop(const ClosedLoopRun& run, std::ostream& progress) {
  ClosedLoopOutcome outcome;
  std::filesystem::create_directories(run.dir);
  std::vector<std::string> words = {
      "scenario:=" + run.scenario,
      "scene:=" + run.scene,
      "object:=" + run.object,
      "symmetry:=" + run.symmetry,
      "tracking:=" + bool_word(run.tracking),
      "code_correction:=" + bool_word(run.code_correction),
      "duration_s:=" + std::to_string(run.duration_s),
      "run_dir:=" + std::filesystem::absolute(run.dir).string(),
      "port:=" + std::to_string(free_tcp_port()),
  };
  if (!run.notes.empty()) words.push_back("notes:=" + run.notes);
  for (const auto& [name, value] : run.extra_args) words.push_back(name + ":=" + value);
  auto graph = load_or_report(closed_loop_graph().string(), words);
  if (!graph) return outcome;
  graph->domain_id = choose_closed_loop_domain(run, progress);
  if (!run.bag.empty()) graph->containers.front().components.push_back(bag_recorder(run));
  if (run.realtime_factor) {
    // Paced by the wall clock (docs/graphs.md, clock: mode realtime): the camera does not wait
    // for decode any more, stages that fall behind skip to the newest input and count it.
    graph->clock.mode = graph::ClockSpec::Mode::realtime;
    graph->clock.real_time_factor = *run.realtime_factor;
  }
  const graph::ContainerSpec& spec = graph->containers.front();

  // Ctrl-C / SIGTERM go to a waiter thread that stops the container: the components are
  // deactivated, the recorder flushes, and the report is made from what was recorded.
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, &previous);

  runtime::Container container(*graph, spec);
  std::atomic<bool> done{false};
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    if (!done.load()) {
      g_run_interrupted = true;
      outcome.interrupted = true;
      container.stop();
    }
  });
  std::thread status_thread;
  int status = 1;
  {
    const bool tty = isatty(STDERR_FILENO) != 0;
    const auto started = std::chrono::steady_clock::now();
    std::atomic<bool> running{true};
    status_thread = std::thread([&] {
      int ticks = 0;
      while (running.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        if (!running.load()) break;
        if (++ticks % (tty ? 2 : 20) != 0) continue;  // 0.5 s on a terminal, 5 s in a log
        const auto* recorder = dynamic_cast<const run_recorder::RunRecorderComponent*>(
            container.find_component("recorder"));
        const double wall_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        const std::string line =
            progress_line(container, recorder != nullptr ? &recorder->progress() : nullptr,
                          run.duration_s, wall_s);
        progress << (tty ? "\r\033[K" : "") << "[" << run.scenario << "] " << line
                 << (tty ? "" : "\n") << std::flush;
      }
    });
    try {
      status = container.run();
    } catch (const std::exception& e) {
      std::cerr << "avs: " << run.scenario << ": " << e.what() << "\n";
    }
    running = false;
    status_thread.join();
    if (tty) progress << "\n";
  }
  done = true;
  pthread_kill(waiter.native_handle(), SIGTERM);  // release the waiter if no signal came
  waiter.join();
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  outcome.status = status;
  if (status != 0 && !outcome.interrupted) {
    std::cerr << "avs: the " << run.scenario << " graph failed (status " << status << ")\n";
  }
  return outcome;
}

}  // namespace avs::cli
