// avs demo: the main job. The simulated closed loop of the paper (projector-camera with
// Gray-code depth at 500 Hz, active tracking by the pan/tilt head, model matching of the
// kendama's ken on the manipulator trajectory) in sim-time lockstep (or, with --realtime,
// paced by the wall clock), with progress, the results table beside the paper's figures, and
// the report folder (figures, index.html).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "avs/report/report.hpp"
#include "avs/runtime/error.hpp"
#include "closed_loop.hpp"
#include "commands.hpp"
#include "live_view.hpp"

namespace avs::cli {

namespace {

std::filesystem::path default_run_dir(const std::string& name) {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  return std::filesystem::path("avs-runs") / (name + "-" + stamp);
}

/// "object=NAME" for the page (docs/view.md): the error panel compares the pose with the
/// /sim/ground_truth of that object, which is the run's object (as run_recorder's).
std::string page_object_query(const std::string& object) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string query = "object=";
  for (const unsigned char c : object) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      query += static_cast<char>(c);
    } else {  // percent-encoded (RFC 3986), e.g. a mesh file's path
      query += '%';
      query += kHex[c >> 4];
      query += kHex[c & 15];
    }
  }
  return query;
}

std::string format_factor(double factor) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", factor);
  return text;
}

/// `--realtime FACTOR`: the factor, or with `auto` 0.8 x the real-time factor a 0.2 s lockstep
/// run of the same loop reaches here (the fastest pace this machine sustains, with a margin);
/// nullopt after saying what is wrong.
std::optional<double> realtime_factor(const std::string& text, const ClosedLoopRun& run,
                                      std::ostream& err) {
  if (text != "auto" && !text.empty()) {
    char* end = nullptr;
    const double f = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !(f > 0.0 && f <= 1.0)) {
      err << "avs demo: --realtime " << text << ": expected a factor in (0, 1] or auto\n";
      return std::nullopt;
    }
    return f;
  }
  ClosedLoopRun probe = run;
  probe.duration_s = 0.2;
  probe.realtime_factor.reset();
  probe.dir = run.dir / "realtime_probe";
  err << "avs demo: --realtime auto: measuring this machine's pace with 0.2 s of lockstep\n";
  const auto started = std::chrono::steady_clock::now();
  const ClosedLoopOutcome outcome = run_closed_loop(probe, err);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::error_code ignored;
  std::filesystem::remove_all(probe.dir, ignored);
  if (outcome.status != 0 || outcome.interrupted || !(wall_s > 0.0)) {
    err << "avs demo: --realtime auto: the measuring run failed; give a factor\n";
    return std::nullopt;
  }
  // Start-up (model loading, connecting) is in wall_s too: the estimate errs on the slow side.
  const double factor = std::min(1.0, 0.8 * probe.duration_s / wall_s);
  err << "avs demo: --realtime auto: 0.2 s of lockstep took " << format_factor(wall_s)
      << " s here; pacing at " << format_factor(factor) << " x real time\n";
  return factor;
}

}  // namespace

void add_demo_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "demo",
      "Run the simulated closed loop (depth at 500 Hz, active tracking, model matching of the "
      "ken on the manipulator trajectory) and report it beside the paper's figures");
  static ClosedLoopRun run;
  static std::string out;
  static bool no_tracking = false;
  cmd->add_option("--seconds", run.duration_s, "simulated time to run")
      ->capture_default_str()
      ->check_range(0.01, 3600);
  cmd->add_option("--out", out, "run folder (default avs-runs/demo-<date>)");
  cmd->add_option("--scene", run.scene, "scene: a name in launch_config/scenes/ or a YAML file")
      ->capture_default_str();
  cmd->add_option("--object", run.object, "model to match: ken, cube, cylinder or a mesh file")
      ->capture_default_str();
  cmd->add_option("--symmetry", run.symmetry, "object symmetry: none, cube, cylinder_x|y|z")
      ->capture_default_str();
  cmd->add_flag("--no-tracking", no_tracking, "the head holds still (Sec. 7.1.2)");
  static LiveViewFlags view;
  add_live_view_options(cmd, view, "the run");
  static std::string realtime;
  static Option* realtime_option = nullptr;
  realtime_option =
      cmd->add_option("--realtime", realtime,
                      "[FACTOR] pace simulated time by the wall clock at FACTOR x real time "
                      "(0 < FACTOR <= 1) instead of lockstep; `auto` or no value: 0.8 x the factor "
                      "this machine reaches in a 0.2 s lockstep run of the same loop")
          ->optional_value();
  static std::string calibration;
  cmd->add_option("--calibration", calibration,
                  "sensor calibration YAML (docs/decode.md) for the simulated sensor and the "
                  "decoder; the other components take it from /depth/camera_info")
      ->check_existing_file();
  static std::string bag;
  cmd->add_option("--bag", bag,
                  "also record --bag-topics into this MCAP file (overwritten; lockstep waits "
                  "for the recorder, so nothing is lost): e.g. the camera stream that avs bench "
                  "pipeline --bag replays");
  cmd->add_option("--bag-topics", run.bag_topics, "comma-separated topics --bag records")
      ->capture_default_str();
  cmd->callback([] {
    run.scenario = "demo";
    if (!bag.empty()) run.bag = std::filesystem::absolute(bag);
    run.tracking = !no_tracking;
    if (!calibration.empty()) {
      run.extra_args["calibration"] = std::filesystem::absolute(calibration).string();
    }
    // Absolute: the report runs gnuplot inside the run folder.
    run.dir = std::filesystem::absolute(out.empty() ? default_run_dir("demo")
                                                    : std::filesystem::path(out));
    if (realtime_option->given()) {
      const std::optional<double> factor = realtime_factor(realtime, run, std::cerr);
      if (!factor) {
        exit_status() = 2;
        return;
      }
      run.realtime_factor = *factor;
      run.notes = "paced by the wall clock at " + format_factor(*factor) +
                  " x real time (avs demo --realtime)";
    }
    std::cerr << "avs demo: simulated closed loop, " << run.duration_s << " s of sim time "
              << (run.realtime_factor ? "paced by the wall clock at " +
                                            format_factor(*run.realtime_factor) + " x real time"
                                      : std::string("in lockstep"))
              << " (graph " << closed_loop_graph().string() << ", scene " << run.scene
              << "); Ctrl-C ends it early with a partial report\n";
    const std::unique_ptr<view::View> live =
        view.enabled ? start_live_view(view, choose_closed_loop_domain(run, std::cerr), "",
                                       "avs demo", std::cerr, page_object_query(run.object))
                     : nullptr;
    const ClosedLoopOutcome outcome = run_closed_loop(run, std::cerr);
    if (live) live->stop();
    if (outcome.interrupted) std::cerr << "avs demo: interrupted: partial report\n";
    const int report_status = report::report_main(run.dir);
    exit_status() = outcome.status != 0 ? outcome.status : report_status;
  });
}

}  // namespace avs::cli
