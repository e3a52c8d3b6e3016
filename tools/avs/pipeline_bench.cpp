// avs bench pipeline: the vision pipeline (decode -> tracking -> matching) against the wall
// clock (issue 16). A pattern_replay source hands a rendered /camera/pattern stream (the ken on
// the manipulator trajectory) to the graph at 1000 fps on an absolute grid; an in-process
// probe beside matching counts every output by stamp and measures the end-to-end latency from
// the hand-over of a pair's negative frame to the arrival of its pose. Placements:
//   intra_process  source and pipeline in one container (copy-free delivery)
//   udp            the source in a child `avs container` process, DDS over UDP loopback
//   shm            the same through iceoryx shared memory (RouDi started by the bench)
// The Cyclone configuration is the one a deployment generates for one host on `lo` (what
// `avs launch` gives its containers), as in `avs bench transport`.
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <tuple>
#include <unordered_map>

#include "avs/bench/report.hpp"
#include "avs/deploy/deployment.hpp"
#include "avs/deploy/roudi.hpp"
#include "avs/report/plots.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/error.hpp"
#include "avs_child.hpp"
#include "dds_environment.hpp"
#include "graph_loading.hpp"
#include "host_stall_probe.hpp"

namespace avs::cli {
namespace {

namespace fs = std::filesystem;

double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::int64_t stamp_ns(const msgs::builtin_interfaces::Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nanosec;
}

// ---- the probe: one in-process subscriber of every output ------------------------------------

/// What the probe saw (read after the container stopped).
struct ProbeData {
  std::vector<double> pose_latency_ms;  ///< per /object/pose: arrival - stamp
  std::vector<double> pose_at_s;        ///< arrival, seconds after the first depth map
  std::vector<double> depth_latency_ms;
  std::map<std::string, std::vector<double>> stage_ms;  ///< /timing by stage
  std::int64_t depth = 0, targets = 0, matches = 0, poses = 0;
  /// Per depth-map stamp: 1 depth seen, 2 target seen, 4 match seen.
  std::unordered_map<std::int64_t, std::uint8_t> seen;
  std::int64_t first_depth_ns = 0, last_depth_ns = 0, first_pose_ns = 0, last_pose_ns = 0;
  double cpu_first_s = 0, cpu_last_s = 0;
};

class PipelineProbe final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    runtime::QosProfile deep;
    deep.depth = 1000;
    return {.type = "bench_pipeline_probe",
            .description =
                "avs bench pipeline: counts /depth/image, /target, /object/match and "
                "/object/pose by stamp, measures the latency of each pose from its "
                "stamp, collects /timing",
            .subscribes = {
                runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image", deep),
                runtime::port<msgs::avs_msgs::TargetObservation>("target", "/target", deep),
                runtime::port<msgs::avs_msgs::MatchResult>("match", "/object/match", deep),
                runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose", deep),
                runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing", deep)}};
  }

  explicit PipelineProbe(runtime::ComponentContext& ctx) : Component(ctx) {
    data_.pose_latency_ms.reserve(1 << 16);
    data_.pose_at_s.reserve(1 << 16);
    data_.depth_latency_ms.reserve(1 << 16);
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) {
          const std::int64_t now = context().now().ns;
          const std::int64_t stamp = stamp_ns(m->header.stamp);
          std::lock_guard lock(mutex_);
          if (data_.depth == 0) {
            data_.first_depth_ns = now;
            data_.cpu_first_s = process_cpu_s();
          }
          data_.last_depth_ns = now;
          data_.cpu_last_s = process_cpu_s();
          ++data_.depth;
          data_.seen[stamp] |= 1;
          data_.depth_latency_ms.push_back(1e-6 * static_cast<double>(now - stamp));
        });
    ctx.subscribe<msgs::avs_msgs::TargetObservation>(
        "target", [this](runtime::SamplePtr<msgs::avs_msgs::TargetObservation> m) {
          std::lock_guard lock(mutex_);
          ++data_.targets;
          data_.seen[stamp_ns(m->header.stamp)] |= 2;
        });
    ctx.subscribe<msgs::avs_msgs::MatchResult>(
        "match", [this](runtime::SamplePtr<msgs::avs_msgs::MatchResult> m) {
          std::lock_guard lock(mutex_);
          ++data_.matches;
          data_.seen[stamp_ns(m->header.stamp)] |= 4;
        });
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) {
          const std::int64_t now = context().now().ns;
          std::lock_guard lock(mutex_);
          if (data_.poses == 0) data_.first_pose_ns = now;
          data_.last_pose_ns = now;
          ++data_.poses;
          data_.pose_latency_ms.push_back(1e-6 *
                                          static_cast<double>(now - stamp_ns(m->header.stamp)));
          data_.pose_at_s.push_back(1e-9 * static_cast<double>(now - data_.first_depth_ns));
        });
    ctx.subscribe<msgs::avs_msgs::StageTiming>(
        "timing", [this](runtime::SamplePtr<msgs::avs_msgs::StageTiming> m) {
          std::lock_guard lock(mutex_);
          data_.stage_ms[std::string(runtime::get_string(m->stage))].push_back(m->processing_ms);
        });
  }

  ProbeData data() const {
    std::lock_guard lock(mutex_);
    return data_;
  }
  std::int64_t depth_count() const {
    std::lock_guard lock(mutex_);
    return data_.depth;
  }

 private:
  mutable std::mutex mutex_;
  ProbeData data_;
};

AVS_REGISTER_COMPONENT(PipelineProbe);

// ---- options ----------------------------------------------------------------------------------

/// Where the replayed /camera/pattern stream comes from.
enum class Source {
  closed_loop,  ///< a bag recorded from the lockstep closed loop (the head follows the ken)
  still_head,   ///< rendered by pattern_replay with the head still (the ken leaves the view)
};

struct Options {
  double seconds = 30;
  int recorded_frames = 1008;
  Source source = Source::closed_loop;
  int cpu_load = 0;  ///< busy processes beside the bench (overload, section 3)
  fs::path bag;  ///< a recording to replay; empty with closed_loop: record <dir>/closed_loop.mcap
  std::vector<std::string> placements{"intra_process", "udp", "shm"};
  fs::path dir = "avs_bench_pipeline";
};

Options parse_options(const std::vector<std::string>& raw) {
  Options o;
  bench::Options given("pipeline", raw, {"--help", "-h"});
  if (given.flag("--help") || given.flag("-h")) {
    std::printf(
        "avs bench pipeline [--json] [--seconds=S] [--placements=intra_process,udp,shm]\n"
        "                   [--recorded-frames=N] [--dir=DIR] [--source=closed_loop|still_head]\n"
        "                   [--bag=FILE]\n"
        "Replays N recorded /camera/pattern frames (the ken on the manipulator trajectory from\n"
        "t = 0.5 s, forwards and backwards by cycle) at 1000 fps of wall-clock time for S\n"
        "seconds per placement into decode -> tracking -> matching; writes latency figures and\n"
        "CSV to DIR (default ./avs_bench_pipeline).\n"
        "  --source=closed_loop  (default) the stream a rig's camera sees while the head follows\n"
        "                        the ken: recorded first from the lockstep closed loop into\n"
        "                        DIR/closed_loop.mcap (a few seconds per 100 frames), or --bag\n"
        "  --bag=FILE            replay this MCAP recording of /camera/pattern (whole cycles from\n"
        "                        stamp 0.5 s; record one with avs launch closed_loop.yaml and\n"
        "                        avs bag record /camera/pattern: lockstep waits for the recorder)\n"
        "  --source=still_head   frames rendered with the head still: the ken leaves the view\n"
        "                        in mid-swing (the bench before 2026-12-06)\n"
        "  --cpu-load=N          N processes that spin on the CPU during the placements (an\n"
        "                        overloaded host: stages skip to the newest input and count it)\n");
    std::exit(0);
  }
  o.seconds = given.number("--seconds", o.seconds, 0.1, 3600.0);
  o.recorded_frames =
      static_cast<int>(given.integer("--recorded-frames", o.recorded_frames, 1, 100000));
  o.dir = given.text("--dir", o.dir.string());
  if (const std::string v = given.text("--source", "closed_loop"); v == "still_head") {
    o.source = Source::still_head;
  } else if (v != "closed_loop") {
    throw runtime::Error("avs bench pipeline: unknown --source '" + v +
                         "' (closed_loop, still_head)");
  }
  o.bag = given.text("--bag", "");
  o.cpu_load = static_cast<int>(given.integer("--cpu-load", 0, 0, 64));
  if (!o.bag.empty() && o.source != Source::closed_loop) {
    throw runtime::Error(
        "avs bench pipeline: --bag replays a recording; --source=still_head "
        "renders one (give one of them)");
  }
  if (!o.bag.empty() && !fs::is_regular_file(o.bag)) {
    throw runtime::Error("avs bench pipeline: --bag " + o.bag.string() + ": no such file");
  }
  if (const std::string v = given.text("--placements", ""); !v.empty()) {
    o.placements.clear();
    std::stringstream ss(v);
    std::vector<std::string> asked;
    for (std::string p; std::getline(ss, p, ',');) {
      if (p != "intra_process" && p != "udp" && p != "shm") {
        throw runtime::Error("avs bench pipeline: unknown placement '" + p +
                             "' (intra_process, udp, shm)");
      }
      asked.push_back(p);
    }
    // Always in this order: shm must be the last (see pipeline_bench).
    for (const char* p : {"intra_process", "udp", "shm"}) {
      if (std::find(asked.begin(), asked.end(), p) != asked.end()) o.placements.push_back(p);
    }
  }
  given.finish();
  return o;
}

// ---- the graph --------------------------------------------------------------------------------

constexpr double kSourceStartDelayS = 2.0;  ///< after activation: discovery, other activations
constexpr double kRecordingStartS = 0.5;    ///< the manipulator starts to move (scene time)

/// Records the closed loop's /camera/pattern (lockstep, ken on the manipulator trajectory, the
/// head following it) into `bag`, long enough for recorded_frames frames from
/// kRecordingStartS: `avs demo --bag` in a child process, so that this process's DDS domain
/// keeps the configuration the placements set up.
void record_closed_loop(const Options& o, const fs::path& bag, const std::string& xml, int domain) {
  const double seconds = kRecordingStartS + 1e-3 * o.recorded_frames + 0.05;
  const fs::path dir = fs::absolute(o.dir);
  std::cerr << "avs bench pipeline: recording the closed loop's /camera/pattern (avs demo, "
            << seconds << " s of simulated time, lockstep) into " << bag.string() << " (log "
            << (dir / "closed_loop_run.log").string() << ")\n";
  AvsChild demo({"demo", "--seconds", std::to_string(seconds), "--out",
                 (dir / "closed_loop_run").string(), "--bag", bag.string()},
                xml, domain, dir / "closed_loop_run.log", "the closed-loop recording");
  const int status = demo.wait();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !fs::is_regular_file(bag)) {
    throw runtime::Error("avs bench pipeline: recording the closed loop failed (see " +
                         (dir / "closed_loop_run.log").string() + ")");
  }
}

/// The bench graph: containers "all" (source + pipeline, intra_process) or "source" and
/// "pipeline" (the other placements). The pipeline's parameters are closed_loop.yaml's.
std::string graph_yaml(const Options& o, bool one_container, const fs::path& source_report,
                       double duration_s) {
  std::ostringstream source;
  source << "      - type: pattern_replay\n        name: source\n        parameters: {"
         << "scene: manipulator_ken, recorded_frames: " << o.recorded_frames
         << ", start_time_s: " << kRecordingStartS;
  if (!o.bag.empty()) source << ", bag: '" << fs::absolute(o.bag).string() << "'";
  source << ", rate_hz: 1000, wait_for_readers: " << (one_container ? 0 : 1)
         << ", start_delay_s: " << kSourceStartDelayS << ", duration_s: " << o.seconds
         << ", report_file: " << source_report.string() << "}\n";
  const std::string pipeline =
      "      - {type: decode, name: decode, parameters: {code_correction: true, "
      "subcode_half_window: 4}}\n"
      "      - {type: tracking, name: tracking}\n"
      "      - type: matching\n        name: matching\n        parameters: {model: ken, "
      "lag_compensation_s: 0.009, velocity_window_s: 0.03, icp_model: dense, "
      "icp_max_distance_m: 0.015, scene_points: 500, scene_voxel_m: 0.005, "
      "outlier_neighbours: 8, icp_iterations: [0, 0, 2], reacquire_within_s: 0.05}\n"
      "      - {type: bench_pipeline_probe, name: probe}\n";
  std::ostringstream y;
  y << "# Written by avs bench pipeline (tools/avs/pipeline_bench.cpp).\n"
    << "clock: {source: wall, duration_s: " << duration_s << "}\ncontainers:\n";
  if (one_container) {
    y << "  - name: all\n    executor: thread_per_component\n    components:\n"
      << source.str() << pipeline;
  } else {
    y << "  - name: source\n    executor: single_threaded\n    components:\n" << source.str();
    y << "  - name: pipeline\n    executor: thread_per_component\n    components:\n" << pipeline;
  }
  return y.str();
}

/// "key=value" words of the source's report file.
std::map<std::string, double> read_report_file(const fs::path& file) {
  std::map<std::string, double> values;
  std::ifstream in(file);
  for (std::string word; in >> word;) {
    const auto eq = word.find('=');
    if (eq != std::string::npos) values[word.substr(0, eq)] = std::atof(word.c_str() + eq + 1);
  }
  return values;
}

std::int64_t diagnostic(const runtime::Component* c, const std::string& key) {
  if (c == nullptr) return 0;
  for (const auto& [k, v] : c->diagnostic_values()) {
    if (k == key) return std::atoll(v.c_str());
  }
  return 0;
}

// ---- one placement ----------------------------------------------------------------------------

struct Percentiles {
  double p50 = 0, p99 = 0, p999 = 0, max = 0;
};

Percentiles percentiles(std::vector<double> v) {
  Percentiles p;
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  };
  return {at(0.5), at(0.99), at(0.999), v.back()};
}

struct PlacementResult {
  std::string name;
  ProbeData probe;
  double depth_rate_hz = 0, pose_rate_hz = 0;
  std::int64_t negatives = 0, missed_slots = 0, decode_dropped = 0, decode_out_of_order = 0;
  std::int64_t late_frames = 0;  ///< handed over a period or more after their slot
  double max_late_ms = 0;
  std::int64_t depth_missing = 0, tracking_missing = 0, matching_missing = 0;
  double cpu_percent_pipeline = 0, cpu_percent_source = -1;  ///< -1: same process
  std::string transport;
  std::string loadavg;
  /// Wake-ups of a 1 kHz sleeper in the bench process more than 3 ms late during the
  /// placement's run, start-up included (HostStallProbe): the host's stalls and, here, the
  /// contention of the run's own threads for the cores.
  int host_stalls = 0;
  double host_stall_max_ms = 0;
  std::int64_t dropped() const {
    return decode_dropped + decode_out_of_order + depth_missing + tracking_missing +
           matching_missing;
  }
};

PlacementResult run_placement(const Options& o, const std::string& placement, int domain,
                              const std::string& xml) {
  PlacementResult r;
  r.name = placement;
  const bool intra = placement == "intra_process";
  const fs::path dir = fs::absolute(o.dir);
  const fs::path graph_file = dir / (placement + "_graph.yaml");
  const fs::path source_report = dir / (placement + "_source.txt");
  fs::remove(source_report);
  // The one container stops 2 s after the source's last frame (intra_process); across
  // processes the bench stops both.
  const double duration_s = intra ? kSourceStartDelayS + o.seconds + 2.0 : 0.0;
  {
    std::ofstream out(graph_file);
    out << graph_yaml(o, intra, source_report, duration_s);
  }
  setenv("CYCLONEDDS_URI", xml.c_str(), 1);
  auto graph = load_or_report(graph_file.string(), {});
  if (!graph) throw runtime::Error("avs bench pipeline: the generated graph did not load");
  graph->domain_id = domain;
  const graph::ContainerSpec& spec =
      *std::find_if(graph->containers.begin(), graph->containers.end(),
                    [&](const graph::ContainerSpec& c) { return c.name != "source"; });
  runtime::Container container(*graph, spec);
  int status = 1;
  const HostStallProbe stalls;
  std::thread runner([&] { status = container.run(); });
  if (intra) {
    runner.join();
  } else {
    int child_status = 0;
    {
      // The source as `avs container FILE --name source`; stderr to its log.
      AvsChild source({"container", graph_file.string(), "--name", "source"}, xml, domain,
                      dir / (placement + "_source.log"), "avs bench pipeline");
      // The source waits for decode's reader, then for its start delay; it replays for
      // o.seconds from its first frame. Then it is stopped (SIGTERM: it writes its report).
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
      for (;;) {
        const auto* probe = dynamic_cast<const PipelineProbe*>(container.find_component("probe"));
        if (probe != nullptr && probe->depth_count() > 0) break;
        if (std::chrono::steady_clock::now() > give_up) {
          container.stop();
          runner.join();
          throw runtime::Error(
              "avs bench pipeline: no depth map within 120 s of starting the "
              "source process; see " +
              (dir / (placement + "_source.log")).string());
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds + 1.0));
      source.terminate();
      child_status = source.wait();
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    container.stop();
    runner.join();
    if (!WIFEXITED(child_status) || WEXITSTATUS(child_status) != 0) {
      throw runtime::Error("avs bench pipeline: the source process failed (status " +
                           std::to_string(child_status) + "); see " +
                           (dir / (placement + "_source.log")).string());
    }
    const auto values = read_report_file(source_report);
    if (values.count("cpu_s") != 0 && values.count("replay_s") != 0 && values.at("replay_s") > 0) {
      r.cpu_percent_source = 100.0 * values.at("cpu_s") / values.at("replay_s");
    }
  }
  if (status != 0) throw runtime::Error("avs bench pipeline: the " + placement + " graph failed");

  const auto* probe = dynamic_cast<const PipelineProbe*>(container.find_component("probe"));
  if (probe == nullptr) throw runtime::Error("avs bench pipeline: no probe");
  r.probe = probe->data();
  const auto source = read_report_file(source_report);
  if (source.empty()) {
    throw runtime::Error("avs bench pipeline: the source wrote no report (" +
                         source_report.string() + ")");
  }
  r.negatives = static_cast<std::int64_t>(source.at("negatives"));
  r.missed_slots = static_cast<std::int64_t>(source.at("missed_slots"));
  r.late_frames = static_cast<std::int64_t>(source.at("late_frames"));
  r.max_late_ms = source.at("max_late_ms");
  const runtime::Component* decode = container.find_component("decode");
  r.decode_dropped = diagnostic(decode, "dropped_frames");
  r.decode_out_of_order = diagnostic(decode, "out_of_order_frames");
  // Every negative handed over makes a depth map once the decoder has seen a whole cycle
  // (before that the map is incomplete): the first 9 negatives may give none.
  const std::int64_t warm_up = 9;
  r.depth_missing = std::max<std::int64_t>(0, r.negatives - warm_up - r.probe.depth);
  for (const auto& [stamp, flags] : r.probe.seen) {
    if ((flags & 1) == 0) continue;
    if ((flags & 2) == 0) ++r.tracking_missing;
    if ((flags & 4) == 0) ++r.matching_missing;
  }
  const ProbeData& p = r.probe;
  if (p.depth > 1) {
    r.depth_rate_hz = static_cast<double>(p.depth - 1) /
                      (1e-9 * static_cast<double>(p.last_depth_ns - p.first_depth_ns));
    r.cpu_percent_pipeline = 100.0 * (p.cpu_last_s - p.cpu_first_s) /
                             (1e-9 * static_cast<double>(p.last_depth_ns - p.first_depth_ns));
  }
  if (p.poses > 1) {
    r.pose_rate_hz = static_cast<double>(p.poses - 1) /
                     (1e-9 * static_cast<double>(p.last_pose_ns - p.first_pose_ns));
  }
  r.loadavg = bench::load_average();
  std::tie(r.host_stalls, r.host_stall_max_ms) = stalls.since(0.0);
  stalls.write_csv((dir / (placement + "_stalls.csv")).string());
  return r;
}

// ---- figures ----------------------------------------------------------------------------------

/// latency_<placement>.csv (t_s, latency_ms) and two PNGs: histogram and latency over time.
std::vector<std::string> write_figures(const fs::path& dir,
                                       const std::vector<PlacementResult>& rs) {
  std::vector<std::string> notes;
  std::ostringstream hist, time;
  hist << "set terminal pngcairo size 1000,650 noenhanced font 'sans,10'\n"
       << "set output 'latency_histogram.png'\nset grid\nset datafile separator ','\n"
       << "set title 'End-to-end latency: negative frame handed over -> its pose (avs bench "
          "pipeline)'\n"
       << "set xlabel 'latency [ms]'\nset ylabel 'poses'\nset logscale y\nset style fill "
          "transparent solid 0.4\nbin(x) = 0.05 * floor(x / 0.05)\n"
       << "set arrow from 2, graph 0 to 2, graph 1 nohead dt 2\nset label 'paper: 2 ms' at 2, "
          "graph 0.95 offset 0.5,0\n";
  time << "set terminal pngcairo size 1000,650 noenhanced font 'sans,10'\n"
       << "set output 'latency_over_time.png'\nset grid\nset datafile separator ','\n"
       << "set title 'End-to-end latency over the run (avs bench pipeline)'\n"
       << "set xlabel 'time since the first depth map [s]'\nset ylabel 'latency [ms]'\n";
  std::string hist_plots, time_plots;
  for (const PlacementResult& r : rs) {
    const std::string csv = "latency_" + r.name + ".csv";
    std::ofstream out(dir / csv);
    out << "t_s,latency_ms\n";
    for (std::size_t i = 0; i < r.probe.pose_latency_ms.size(); ++i) {
      out << r.probe.pose_at_s[i] << "," << r.probe.pose_latency_ms[i] << "\n";
    }
    hist_plots += (hist_plots.empty() ? "plot " : ", ") + std::string("'") + csv +
                  "' every ::1 using (bin($2)):(1) smooth frequency with boxes title '" + r.name +
                  "'";
    time_plots += (time_plots.empty() ? "plot " : ", ") + std::string("'") + csv +
                  "' every ::1 using 1:2 with points pt 7 ps 0.3 title '" + r.name + "'";
  }
  if (hist_plots.empty()) return notes;
  hist << hist_plots << "\n";
  time << time_plots << "\n";
  for (const auto& [file, text] : {std::pair{"latency_histogram.gp", hist.str()},
                                   std::pair{"latency_over_time.gp", time.str()}}) {
    std::ofstream(dir / file) << text;
    try {
      (void)report::run_gnuplot(dir, file);
    } catch (const std::exception& e) {
      notes.push_back(std::string("figure not made (") + file + "): " + e.what());
    }
  }
  notes.push_back("figures: " + (dir / "latency_histogram.png").string() + ", " +
                  (dir / "latency_over_time.png").string());
  return notes;
}

// ---- the bench --------------------------------------------------------------------------------

void add_rows(bench::Report& report, const PlacementResult& r) {
  const std::string& n = r.name;
  const Percentiles lat = percentiles(r.probe.pose_latency_ms);
  const std::string paper_rate = "paper (Sec. 7, 500 Hz)";
  report.rows.push_back({n + ": depth maps per second", "Hz", r.depth_rate_hz, paper_rate, 500});
  report.rows.push_back({n + ": poses per second", "Hz", r.pose_rate_hz, paper_rate, 500});
  const std::string paper_latency = "paper: pose within 2 ms (Sec. 7.2.1)";
  report.rows.push_back({n + ": latency p50 (negative -> pose)", "ms", lat.p50, paper_latency, 2});
  report.rows.push_back({n + ": latency p99", "ms", lat.p99, paper_latency, 2});
  report.rows.push_back({n + ": latency p99.9", "ms", lat.p999, paper_latency, 2});
  report.rows.push_back({n + ": latency max", "ms", lat.max, paper_latency, 2});
  const std::map<std::string, std::pair<std::string, double>> paper_stage = {
      {"decode", {"paper: depth ~1.5 ms (Sec. 7.1.1)", 1.5}},
      {"matching", {"paper: ~1 ms, < 1.5 ms (Fig. 13b)", 1.0}}};
  for (const auto& [stage, times] : r.probe.stage_ms) {
    const Percentiles t = percentiles(times);
    const auto peer = paper_stage.find(stage);
    const std::string peer_name = peer != paper_stage.end() ? peer->second.first : "";
    const double peer_ms = peer != paper_stage.end() ? peer->second.second : 0;
    report.rows.push_back({n + ": " + stage + " time p50", "ms", t.p50, peer_name, peer_ms});
    report.rows.push_back({n + ": " + stage + " time p99", "ms", t.p99, "", 0});
    report.rows.push_back({n + ": " + stage + " time max", "ms", t.max, "", 0});
    report.json["placement." + n + "." + stage + "_ms_p50"] = t.p50;
    report.json["placement." + n + "." + stage + "_ms_p99"] = t.p99;
    report.json["placement." + n + "." + stage + "_ms_max"] = t.max;
  }
  report.rows.push_back({n + ": dropped inputs (all stages)", "", static_cast<double>(r.dropped()),
                         "issue 16 goal", 0});
  report.rows.push_back({n + ": CPU, pipeline process", "%", r.cpu_percent_pipeline, "", 0});
  if (r.cpu_percent_source >= 0) {
    report.rows.push_back({n + ": CPU, source process", "%", r.cpu_percent_source, "", 0});
  }
  report.rows.push_back(
      {n + ": stalls (1 kHz sleeper > 3 ms late)", "", static_cast<double>(r.host_stalls), "", 0});
  report.rows.push_back({n + ": longest stall", "ms", r.host_stall_max_ms, "", 0});
  const std::string key = "placement." + n + ".";
  report.json[key + "latency_ms_p50"] = lat.p50;
  report.json[key + "latency_ms_p99"] = lat.p99;
  report.json[key + "latency_ms_p999"] = lat.p999;
  report.json[key + "latency_ms_max"] = lat.max;
  report.json[key + "depth_rate_hz"] = r.depth_rate_hz;
  report.json[key + "pose_rate_hz"] = r.pose_rate_hz;
  report.json[key + "dropped_inputs"] = static_cast<double>(r.dropped());
  report.json[key + "cpu_percent"] = r.cpu_percent_pipeline;
  if (r.cpu_percent_source >= 0) report.json[key + "cpu_percent_source"] = r.cpu_percent_source;
  report.json[key + "poses"] = static_cast<double>(r.probe.poses);
  report.json[key + "depth_maps"] = static_cast<double>(r.probe.depth);
  report.json[key + "source_missed_slots"] = static_cast<double>(r.missed_slots);
  report.json[key + "source_late_frames"] = static_cast<double>(r.late_frames);
  report.json[key + "source_max_late_ms"] = r.max_late_ms;
  report.json[key + "host_stalls"] = static_cast<double>(r.host_stalls);
  report.json[key + "host_stall_max_ms"] = r.host_stall_max_ms;
  report.json[key + "decode_dropped_frames"] = static_cast<double>(r.decode_dropped);
  report.json[key + "decode_out_of_order_frames"] = static_cast<double>(r.decode_out_of_order);
  report.json[key + "depth_missing"] = static_cast<double>(r.depth_missing);
  report.json[key + "tracking_missing"] = static_cast<double>(r.tracking_missing);
  report.json[key + "matching_missing"] = static_cast<double>(r.matching_missing);
  std::ostringstream note;
  note << n << " (" << r.transport << "): " << r.negatives << " negatives handed over, "
       << r.probe.depth << " depth maps, " << r.probe.targets << " targets, " << r.probe.matches
       << " match results, " << r.probe.poses << " poses; dropped: decode sequence gaps "
       << r.decode_dropped << ", out of order " << r.decode_out_of_order
       << ", negatives without depth " << r.depth_missing << ", depth without target "
       << r.tracking_missing << ", depth without match result " << r.matching_missing
       << "; source: " << r.late_frames << " frames handed over late (at most " << r.max_late_ms
       << " ms after their slot, counted in the latency: stamps are slot times), " << r.missed_slots
       << " slots missed (more than the camera's 32 buffers behind); "
       << "load average after it: " << r.loadavg;
  report.notes.push_back(note.str());
}

bench::Report pipeline_bench(const std::vector<std::string>& args) {
  Options o = parse_options(args);
  fs::create_directories(o.dir);
  const int domain = domain_or_environment(181);
  deploy::Deployment d;
  d.hosts.push_back(deploy::Host{"local", "", "lo", {}, {}});
  const std::string udp_xml = deploy::cyclone_config(d, d.hosts[0], "bench");
  d.shared_memory.enabled = true;
  const std::string shm_xml = deploy::cyclone_config(d, d.hosts[0], "bench");
  if (o.source == Source::closed_loop && o.bag.empty()) {
    o.bag = fs::absolute(o.dir) / "closed_loop.mcap";
    record_closed_loop(o, o.bag, udp_xml, domain);
  }

  // The CPU hogs: children that spin until the bench ends (SIGKILL below, or their parent's
  // death: PR_SET_PDEATHSIG).
  std::vector<pid_t> hogs;
  for (int i = 0; i < o.cpu_load; ++i) {
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(0);
      for (;;) asm volatile("");  // spin (a side effect the compiler keeps)
    }
    if (pid < 0) {
      throw runtime::Error(std::string("avs bench pipeline: --cpu-load: cannot start a CPU hog: ") +
                           std::strerror(errno));
    }
    hogs.push_back(pid);
  }
  struct KillHogs {
    std::vector<pid_t>& pids;
    ~KillHogs() {
      for (const pid_t pid : pids) {
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
      }
    }
  } kill_hogs{hogs};

  bench::Report report;
  std::ostringstream title;
  const std::string load_before = bench::load_average();
  title << "avs bench pipeline: /camera/pattern at 1000 fps of wall-clock time for " << o.seconds
        << " s per placement -> decode -> tracking -> matching (ken, manipulator trajectory, "
        << (o.source == Source::closed_loop ? "recorded in the closed loop: " + o.bag.string()
                                            : std::string("rendered, head still"))
        << "); "
        << "load average before: " << load_before << " (2-core machine shared with builds)"
        << (o.cpu_load > 0 ? "; " + std::to_string(o.cpu_load) + " CPU hog process(es) beside it"
                           : std::string());
  report.title = title.str();
  std::vector<PlacementResult> results;
  for (const std::string& placement : o.placements) {
    PlacementResult r;
    if (placement == "shm") {
      try {
        // This process's own participant joins RouDi, and a RouDi that shuts down sends
        // SIGTERM to every process still registered with it. So the RouDi started here lives
        // as long as this process (it ends with it: die_with_parent), and shm runs last.
        static deploy::Roudi* const roudi = new deploy::Roudi();
        r = run_placement(o, placement, domain, shm_xml);
        r.transport = "iceoryx shared memory through " + roudi->description();
      } catch (const std::exception& e) {
        report.notes.push_back("shm not measured: " + std::string(e.what()));
        continue;
      }
    } else {
      r = run_placement(o, placement, domain, udp_xml);
      r.transport = placement == "udp" ? "DDS over UDP loopback" : "one container, copy-free";
    }
    add_rows(report, r);
    results.push_back(std::move(r));
  }
  for (const std::string& note : write_figures(o.dir, results)) report.notes.push_back(note);
  report.notes.push_back(
      "ratio = paper / avs (for rates: above 1 means we are slower than the paper; for times "
      "and latency: above 1 means we are faster). Latency is measured at an in-process "
      "subscriber of /object/pose beside matching; stamps are the frames' slot times on the "
      "absolute 1 ms grid (a camera's exposure stamp), so a late hand-over by the source counts in "
      "the latency.");
  report.json["seconds_per_placement"] = o.seconds;
  report.json["recorded_frames"] = o.recorded_frames;
  report.json["source_closed_loop"] = o.source == Source::closed_loop ? 1 : 0;
  report.json["cpu_load_processes"] = o.cpu_load;
  report.json["load_average_1min_before"] = std::atof(load_before.c_str());
  report.json["load_average_1min_after"] = std::atof(bench::load_average().c_str());
  return report;
}

AVS_REGISTER_BENCH(pipeline, "pipeline",
                   "decode -> tracking -> matching at 1000 fps of wall-clock time: rates, drops, "
                   "latency (intra_process, udp, shm)",
                   pipeline_bench);

}  // namespace
}  // namespace avs::cli
