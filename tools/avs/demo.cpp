// avs demo: the main job. The simulated closed loop of the paper (projector-camera with
// Gray-code depth at 500 Hz, active tracking by the pan/tilt head, model matching of the
// kendama's ken on the manipulator trajectory) in sim-time lockstep, with progress, the
// results table beside the paper's figures, and the report folder (figures, index.html).
#include <cctype>
#include <ctime>
#include <iostream>
#include <memory>
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
  static std::string calibration;
  cmd->add_option("--calibration", calibration,
                  "sensor calibration YAML (docs/decode.md) for the simulated sensor and the "
                  "decoder; the other components take it from /depth/camera_info")
      ->check_existing_file();
  cmd->callback([] {
    run.scenario = "demo";
    run.tracking = !no_tracking;
    if (!calibration.empty()) {
      run.extra_args["calibration"] = std::filesystem::absolute(calibration).string();
    }
    // Absolute: the report runs gnuplot inside the run folder.
    run.dir = std::filesystem::absolute(out.empty() ? default_run_dir("demo")
                                                    : std::filesystem::path(out));
    std::cerr << "avs demo: simulated closed loop, " << run.duration_s << " s of sim time in "
              << "lockstep (graph " << closed_loop_graph().string() << ", scene " << run.scene
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
