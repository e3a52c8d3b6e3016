// avs demo: the main job. The simulated closed loop of the paper (projector-camera with
// Gray-code depth at 500 Hz, active tracking by the pan/tilt head, model matching of the
// kendama's ken on the manipulator trajectory) in sim-time lockstep, with progress, the
// results table beside the paper's figures, and the report folder (figures, index.html).
#include <ctime>
#include <iostream>
#include <memory>

#include "avs/report/report.hpp"
#include "avs/runtime/error.hpp"
#include "avs/view/view.hpp"
#include "closed_loop.hpp"
#include "commands.hpp"

namespace avs::cli {

namespace {

std::filesystem::path default_run_dir(const std::string& name) {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  return std::filesystem::path("avs-runs") / (name + "-" + stamp);
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
  static bool view = false;
  static unsigned view_port = 8765;
  cmd->add_flag("--view", view,
                "serve the run live (avs view: Foxglove WebSocket and the page, docs/view.md)");
  cmd->add_option("--view-port", view_port, "port of --view (0: any free port)")
      ->capture_default_str();
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
    std::unique_ptr<view::View> live;
    if (view) {
      if (view_port > 65535) throw runtime::Error("avs demo: --view-port must be in [0, 65535]");
      view::ViewOptions o;
      o.domain = choose_closed_loop_domain(run, std::cerr);
      o.server.port = static_cast<std::uint16_t>(view_port);
      o.server.web_root = view::built_page_dir();
      live = std::make_unique<view::View>(o);
      live->start();
      std::cerr << "avs demo: live view at http://127.0.0.1:" << live->port()
                << "/ (Foxglove: ws://127.0.0.1:" << live->port() << ")\n";
    }
    const ClosedLoopOutcome outcome = run_closed_loop(run, std::cerr);
    if (live) live->stop();
    if (outcome.interrupted) std::cerr << "avs demo: interrupted: partial report\n";
    const int report_status = report::report_main(run.dir);
    exit_status() = outcome.status != 0 ? outcome.status : report_status;
  });
}

}  // namespace avs::cli
