// avs bench soak --minutes N: the closed loop (launch_config/closed_loop_processes.yaml, one
// process per stage, wall clock) run for N minutes while every container's resident memory and
// open file descriptors are read from /proc each second (issue 20 section 5). After the warm-up
// the growth of each is the slope of a least-squares line through its samples, per minute;
// every loss counter the components report on /diagnostics (dropped, lost, not written, out of
// order, rejected, timeouts, ...) is read at the end of the warm-up and at the end of the run.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "avs/bench/report.hpp"
#include "avs/deploy/deployment.hpp"
#include "avs/report/plots.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/error.hpp"
#include "avs_child.hpp"
#include "dds_environment.hpp"
#include "graph_loading.hpp"
#include "host_stall_probe.hpp"
#include "probe_container.hpp"

namespace avs::cli {
namespace {

namespace fs = std::filesystem;

// ---- the probe: poses and /diagnostics --------------------------------------------------------

/// Whether a /diagnostics key counts something lost or refused.
bool is_loss_counter(const std::string& key) {
  for (const char* word : {"dropped", "lost", "not_written", "out_of_order", "rejected", "timeouts",
                           "missing", "incomplete", "errors", "underruns"}) {
    if (key.find(word) != std::string::npos) return true;
  }
  return false;
}

class SoakProbe final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    runtime::QosProfile deep;
    deep.depth = 100;
    return {.type = "bench_soak_probe",
            .description =
                "avs bench soak: counts /object/pose, keeps the latest value of every "
                "loss counter on /diagnostics",
            .subscribes = {
                runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose", deep),
                runtime::port<msgs::diagnostic_msgs::DiagnosticArray>("diagnostics", "/diagnostics",
                                                                      deep)}};
  }

  explicit SoakProbe(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped>) {
          std::lock_guard lock(mutex_);
          ++poses_;
        });
    ctx.subscribe<msgs::diagnostic_msgs::DiagnosticArray>(
        "diagnostics", [this](runtime::SamplePtr<msgs::diagnostic_msgs::DiagnosticArray> m) {
          std::lock_guard lock(mutex_);
          for (std::uint32_t i = 0; i < m->status._length; ++i) {
            const auto& status = m->status._buffer[i];
            const std::string name(runtime::get_string(status.name));
            for (std::uint32_t j = 0; j < status.values._length; ++j) {
              const std::string key(runtime::get_string(status.values._buffer[j].key));
              if (!is_loss_counter(key)) continue;
              char* end = nullptr;
              const std::string value(runtime::get_string(status.values._buffer[j].value));
              const double v = std::strtod(value.c_str(), &end);
              if (end != value.c_str()) counters_[name + "/" + key] = v;
            }
          }
        });
  }

  std::int64_t poses() const {
    std::lock_guard lock(mutex_);
    return poses_;
  }
  std::map<std::string, double> counters() const {
    std::lock_guard lock(mutex_);
    return counters_;
  }

 private:
  mutable std::mutex mutex_;
  std::int64_t poses_ = 0;
  std::map<std::string, double> counters_;  ///< "<status name>/<key>" -> latest value
};

AVS_REGISTER_COMPONENT(SoakProbe);

// ---- options ----------------------------------------------------------------------------------

struct Options {
  double minutes = 10;
  double warm_up_s = 60;
  fs::path dir = "avs_bench_soak";
  fs::path graph;
  double receive_buffer_kib = 0;  ///< Cyclone's receive-buffer block; 0: its default (1 MiB)
};

Options parse_options(const std::vector<std::string>& raw) {
  Options o;
  o.graph = fs::path(AVS_SOURCE_DIR) / "launch_config" / "closed_loop_processes.yaml";
  bench::Options given("soak", raw, {"--help", "-h"});
  if (given.flag("--help") || given.flag("-h")) {
    std::printf(
        "avs bench soak [--json] [--minutes=N] [--warm-up=S] [--dir=DIR] [--graph=FILE]\n"
        "               [--dds-receive-buffer=KIB]\n"
        "Runs launch_config/closed_loop_processes.yaml for N minutes (default 10) and reads\n"
        "every container's resident memory and open descriptors each second; after S s of\n"
        "warm-up (default 60, at most half the run) prints their growth per minute and the\n"
        "loss counters of /diagnostics that rose. Samples go to DIR/samples.csv, a plot to\n"
        "DIR/soak.png (default DIR ./avs_bench_soak). --dds-receive-buffer=KIB sets Cyclone's\n"
        "receive-buffer block (default 0: Cyclone's 1 MiB, which discovery traffic took 16-18\n"
        "min to fill and recycle in docs/reliability.md's runs).\n");
    std::exit(0);
  }
  o.minutes = given.number("--minutes", o.minutes, 0.1, 10000.0);
  o.warm_up_s = given.number("--warm-up", o.warm_up_s, 0.0, 36000.0);
  o.dir = given.text("--dir", o.dir.string());
  o.graph = given.text("--graph", o.graph.string());
  o.receive_buffer_kib = given.number("--dds-receive-buffer", o.receive_buffer_kib, 0.0, 1048576.0);
  given.finish();
  constexpr double kMinKib = deploy::Transport::kMinReceiveBufferBytes / 1024.0;
  if (o.receive_buffer_kib != 0 && o.receive_buffer_kib < kMinKib) {
    throw runtime::Error("avs bench soak: --dds-receive-buffer=" +
                         std::to_string(static_cast<long>(o.receive_buffer_kib)) +
                         " KiB: use 0 (Cyclone's 1 MiB) or at least " +
                         std::to_string(static_cast<long>(kMinKib)));
  }
  o.warm_up_s = std::min(o.warm_up_s, 30.0 * o.minutes);
  return o;
}

// ---- /proc --------------------------------------------------------------------------------------

/// VmRSS of `pid` in KiB; -1 when it is gone.
double rss_kib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6);
  }
  return -1;
}

/// Open descriptors of `pid`; -1 when it is gone.
double open_fds(pid_t pid) {
  std::error_code ec;
  double n = 0;
  for (fs::directory_iterator it("/proc/" + std::to_string(pid) + "/fd", ec), end; !ec && it != end;
       it.increment(ec)) {
    ++n;
  }
  return ec ? -1 : n;
}

/// Least-squares slope of y over t (per unit of t); NaN with fewer than 2 points.
double slope(const std::vector<double>& t, const std::vector<double>& y) {
  const auto n = static_cast<double>(t.size());
  if (t.size() < 2) return NAN;
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    st += t[i];
    sy += y[i];
    stt += t[i] * t[i];
    sty += t[i] * y[i];
  }
  const double d = n * stt - st * st;
  return d > 0 ? (n * sty - st * sy) / d : NAN;
}

/// Peak of y in the second half of t's span minus its peak in the first half; NaN with fewer
/// than 2 points. Memory that is bounded but filled slowly (a pool touched page by page, then
/// recycled: a sawtooth) shows a positive least-squares slope in any run shorter than about two
/// of its periods, and a peak growth near 0 once each half holds a period; a leak raises the
/// peak by its slope times half the run.
double peak_growth(const std::vector<double>& t, const std::vector<double>& y) {
  if (t.size() < 2) return NAN;
  const double mid = 0.5 * (t.front() + t.back());
  double first = -INFINITY, second = -INFINITY;
  for (std::size_t i = 0; i < t.size(); ++i) {
    double& peak = t[i] < mid ? first : second;
    peak = std::max(peak, y[i]);
  }
  return std::isfinite(first) && std::isfinite(second) ? second - first : NAN;
}

struct Series {
  std::vector<double> t_min, rss_kib, fds;  ///< after the warm-up
  double rss_first = NAN, rss_last = NAN, fds_first = NAN, fds_last = NAN;
  int restarts = 0;  ///< times its pid changed (it died and avs launch started it again)
};

// ---- the bench --------------------------------------------------------------------------------

bench::Report soak_bench(const std::vector<std::string>& args) {
  const Options o = parse_options(args);
  const fs::path dir = fs::absolute(o.dir);
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".mcap") fs::remove(e.path());
  }
  const int domain = domain_or_environment(185);
  deploy::Deployment d;
  d.hosts.push_back(deploy::Host{"local", "", "lo", {}, {}});
  d.transport.receive_buffer_bytes = static_cast<std::uint64_t>(o.receive_buffer_kib * 1024.0);
  const std::string xml = deploy::cyclone_config(d, d.hosts[0], "bench");
  auto graph = load_or_report(o.graph.string(), {});
  if (!graph) throw runtime::Error("avs bench soak: " + o.graph.string() + " did not load");
  std::vector<std::string> containers;
  for (const auto& c : graph->containers) containers.push_back(c.name);

  bench::Report report;
  const std::string load_before = bench::load_average();
  std::ostringstream title;
  title << "avs bench soak: " << o.graph.filename().string() << " for " << o.minutes
        << " min on the wall clock, resident memory and open descriptors of each container "
        << "each second, growth after " << o.warm_up_s
        << " s of warm-up; load average before: " << load_before;
  report.title = title.str();

  ProbeContainer<SoakProbe> probe_container(dir, "bench_soak_probe", xml, domain, "avs bench soak");
  const SoakProbe* probe = &probe_container.probe();

  std::map<std::string, Series> series;
  std::optional<HostStallProbe> stalls;
  std::map<std::string, double> counters_after_warm_up, counters_end;
  std::int64_t poses_after_warm_up = 0, poses_end = 0;
  const fs::path launch_log = dir / "launch.log";
  std::ofstream csv(dir / "samples.csv");
  csv << "t_s,container,rss_kib,fds\n";
  {
    const int port = 20000 + domain;
    AvsChild launcher({"launch", o.graph.string(), "bag:=" + (dir / "soak.mcap").string(),
                       "port:=" + std::to_string(port)},
                      xml, domain, launch_log, "avs bench soak");
    std::fprintf(stderr, "avs bench soak: launched %s for %g min (log %s)\n", o.graph.c_str(),
                 o.minutes, launch_log.c_str());
    std::map<std::string, pid_t> pids;
    stalls.emplace();  // its clock starts with the run's
    const auto start = std::chrono::steady_clock::now();
    const double run_s = 60.0 * o.minutes;
    bool warm = false;
    int last_progress_min = -1;
    for (int k = 0;; ++k) {
      std::this_thread::sleep_until(start + std::chrono::seconds(k));
      const double t_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (t_s > run_s) break;
      if (!launcher.running()) {
        throw runtime::Error("avs bench soak: avs launch ended after " + std::to_string(t_s) +
                             " s; see " + launch_log.string());
      }
      if (!warm && t_s >= o.warm_up_s) {
        warm = true;
        counters_after_warm_up = probe->counters();
        poses_after_warm_up = probe->poses();
      }
      for (const std::string& name : containers) {
        const pid_t pid = container_pid(launcher.pid(), name);
        if (pid <= 0) continue;
        Series& s = series[name];
        if (pids.count(name) != 0 && pids[name] != pid) ++s.restarts;
        pids[name] = pid;
        const double rss = rss_kib(pid), fds = open_fds(pid);
        if (rss < 0 || fds < 0) continue;
        csv << t_s << "," << name << "," << rss << "," << fds << "\n";
        if (!warm) continue;
        s.t_min.push_back(t_s / 60.0);
        s.rss_kib.push_back(rss);
        s.fds.push_back(fds);
        if (std::isnan(s.rss_first)) {
          s.rss_first = rss;
          s.fds_first = fds;
        }
        s.rss_last = rss;
        s.fds_last = fds;
      }
      if (const int minute = static_cast<int>(t_s / 60); minute != last_progress_min) {
        last_progress_min = minute;
        std::fprintf(stderr, "avs bench soak: %d of %g min, %lld poses\n", minute, o.minutes,
                     static_cast<long long>(probe->poses()));
      }
    }
    counters_end = probe->counters();
    poses_end = probe->poses();
    launcher.terminate();
    (void)launcher.wait();
  }
  probe_container.stop();
  csv.close();

  double rss_total_slope = 0, rss_total_peak_growth = 0;
  int restarts = 0;
  for (const std::string& name : containers) {
    const Series& s = series[name];
    const double rss_slope = slope(s.t_min, s.rss_kib), fd_slope = slope(s.t_min, s.fds);
    report.rows.push_back(
        {name + ": resident memory growth after warm-up", "KiB/min", rss_slope, "", 0});
    report.rows.push_back(
        {name + ": open descriptors growth after warm-up", "fds/min", fd_slope, "", 0});
    const double rss_peak_growth = peak_growth(s.t_min, s.rss_kib);
    report.rows.push_back(
        {name + ": peak resident memory, 2nd half minus 1st", "KiB", rss_peak_growth, "", 0});
    report.rows.push_back(
        {name + ": resident memory at the end", "MiB", s.rss_last / 1024.0, "", 0});
    const std::string k = "container." + name + ".";
    report.json[k + "rss_kib_per_min"] = rss_slope;
    report.json[k + "fds_per_min"] = fd_slope;
    report.json[k + "rss_peak_kib_growth_between_halves"] = rss_peak_growth;
    report.json[k + "rss_kib_after_warm_up"] = s.rss_first;
    report.json[k + "rss_kib_end"] = s.rss_last;
    report.json[k + "fds_after_warm_up"] = s.fds_first;
    report.json[k + "fds_end"] = s.fds_last;
    report.json[k + "samples"] = static_cast<double>(s.t_min.size());
    report.json[k + "restarts"] = s.restarts;
    if (!std::isnan(rss_slope)) rss_total_slope += rss_slope;
    if (!std::isnan(rss_peak_growth)) rss_total_peak_growth += rss_peak_growth;
    restarts += s.restarts;
  }
  int rising = 0;
  for (const auto& [key, end] : counters_end) {
    const auto before = counters_after_warm_up.find(key);
    const double at_warm_up = before != counters_after_warm_up.end() ? before->second : 0.0;
    if (end > at_warm_up) {
      ++rising;
      std::ostringstream note;
      note << "loss counter rose after the warm-up: " << key << " " << at_warm_up << " -> " << end;
      report.notes.push_back(note.str());
    }
  }
  const double measured_min = o.minutes - o.warm_up_s / 60.0;
  const double pose_rate_hz =
      measured_min > 0 ? static_cast<double>(poses_end - poses_after_warm_up) / (60 * measured_min)
                       : NAN;
  report.rows.push_back(
      {"all containers: resident memory growth", "KiB/min", rss_total_slope, "", 0});
  report.rows.push_back({"all containers: peak resident memory, 2nd half minus 1st", "KiB",
                         rss_total_peak_growth, "", 0});
  report.rows.push_back({"poses per second after warm-up", "Hz", pose_rate_hz, "", 0});
  report.rows.push_back(
      {"loss counters that rose after warm-up", "", static_cast<double>(rising), "", 0});
  // The host's own stalls beside them: a drive reply later than its timeout, a skipped frame
  // while every thread on the machine stood still is a figure of the host (docs/reliability.md).
  const auto [host_stalls, host_stall_max_ms] = stalls->since(o.warm_up_s);
  stalls->write_csv((dir / "stalls.csv").string());
  report.rows.push_back({"host stalls after warm-up (1 kHz sleeper > 3 ms late)", "",
                         static_cast<double>(host_stalls), "", 0});
  report.rows.push_back({"longest host stall after warm-up", "ms", host_stall_max_ms, "", 0});
  report.json["host_stalls_after_warm_up"] = host_stalls;
  report.json["host_stall_max_ms"] = host_stall_max_ms;
  if (rising > 0 && host_stalls > 0) {
    report.notes.push_back(
        "the host stalled " + std::to_string(host_stalls) + " times after the warm-up (longest " +
        std::to_string(host_stall_max_ms) + " ms; wall-clock times in " +
        (dir / "stalls.csv").string() +
        "): compare them with the times of the loss counters' log lines in " + launch_log.string());
  }
  report.notes.push_back(
      "goal (issue 20 section 5): no growth of memory or descriptors after the warm-up, no loss "
      "counter rising; growth is the least-squares slope of the samples after the warm-up, peak "
      "growth the highest sample of the second half minus that of the first. Cyclone DDS carves "
      "kept messages out of 1 MiB receive buffers (Sizing/ReceiveBufferSize) that discovery "
      "traffic alone filled in 16-18 min in docs/reliability.md's runs: a slope until then, a peak "
      "growth near 0 once each "
      "half is longer (docs/reliability.md, \"Soak\"; --dds-receive-buffer=256 shortens it)");
  report.json["minutes"] = o.minutes;
  report.json["warm_up_s"] = o.warm_up_s;
  report.json["rss_kib_per_min_total"] = rss_total_slope;
  report.json["rss_peak_kib_growth_between_halves_total"] = rss_total_peak_growth;
  report.json["dds_receive_buffer_kib"] = o.receive_buffer_kib;
  report.json["pose_rate_hz"] = pose_rate_hz;
  report.json["loss_counters_rising"] = rising;
  report.json["loss_counters_seen"] = static_cast<double>(counters_end.size());
  report.json["container_restarts"] = restarts;
  report.json["load_average_1min_before"] = std::atof(load_before.c_str());
  report.json["load_average_1min_after"] = std::atof(bench::load_average().c_str());
  {
    // Resident memory and descriptors over the run, one line per container.
    std::string names;
    for (const std::string& name : containers) names += (names.empty() ? "" : " ") + name;
    std::ofstream(dir / "soak.gp")
        << "set terminal pngcairo size 1000,800 noenhanced font 'sans,10'\n"
        << "set output 'soak.png'\nset datafile separator ','\nset grid\nset multiplot layout 2,1\n"
        << "set title 'Resident memory per container (avs bench soak)'\n"
        << "set xlabel 'time [s]'\nset ylabel 'RSS [MiB]'\nset key outside right\n"
        << "set arrow from " << o.warm_up_s << ", graph 0 to " << o.warm_up_s
        << ", graph 1 nohead dt 2\n"
        << "names = '" << names << "'\n"
        << "plot for [c in names] 'samples.csv' every ::1 using 1:(strcol(2) eq c ? $3 / 1024 : "
           "1/0) with points pt 7 ps 0.4 title c\n"
        << "set title 'Open file descriptors per container'\nset ylabel 'descriptors'\n"
        << "plot for [c in names] 'samples.csv' every ::1 using 1:(strcol(2) eq c ? $4 : 1/0) "
           "with points pt 7 ps 0.4 title c\nunset multiplot\n";
    try {
      (void)report::run_gnuplot(dir, "soak.gp");
      report.notes.push_back("figure: " + (dir / "soak.png").string());
    } catch (const std::exception& e) {
      report.notes.push_back(std::string("figure not made: ") + e.what());
    }
  }
  report.notes.push_back(
      "samples: " + (dir / "samples.csv").string() + "; launch log: " + launch_log.string() + "; " +
      std::to_string(counters_end.size()) + " loss counters watched on /diagnostics");
  return report;
}

AVS_REGISTER_BENCH(soak, "soak",
                   "the closed loop for --minutes N: resident memory and descriptors per "
                   "container, growth per minute, loss counters",
                   soak_bench);

}  // namespace
}  // namespace avs::cli
