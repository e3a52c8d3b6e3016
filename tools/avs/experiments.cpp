// avs experiments [NAME...] [--json]: the paper's Sec. 7 as runnable scenarios on the simulated
// closed loop. Each scenario runs the graph anew (nothing is reused or hard-coded), writes its
// run folder with figures and index.html, and prints the paper's figures beside ours.
#include <ctime>
#include <fstream>
#include <iostream>

#include "avs/report/paper.hpp"
#include "avs/report/report.hpp"
#include "avs/report/seeds.hpp"
#include "avs/report/table.hpp"
#include "closed_loop.hpp"
#include "commands.hpp"

namespace avs::cli {

namespace {

struct Experiment {
  std::string name;
  std::string section;
  std::string what;
  ClosedLoopRun run;
};

ClosedLoopRun make_run(std::string scenario, std::string scene, std::string object,
                       std::string symmetry, double duration_s) {
  ClosedLoopRun run;
  run.scenario = std::move(scenario);
  run.scene = std::move(scene);
  run.object = std::move(object);
  run.symmetry = std::move(symmetry);
  run.duration_s = duration_s;
  return run;
}

std::vector<Experiment> experiments() {
  std::vector<Experiment> list;
  {
    Experiment e{"tracking", "7.1.1", "ken swung laterally at 1 m/s, depth with active tracking",
                 make_run("tracking", "swing", "ken", "none", 4.0)};
    list.push_back(e);
    e.name = "no_tracking";
    e.section = "7.1.2";
    e.what = "the same swing with the head held still";
    e.run.scenario = "no_tracking";
    e.run.tracking = false;
    list.push_back(e);
  }
  list.push_back({"ken", "7.2.1", "ken on the manipulator trajectory, tracking and matching",
                  make_run("ken", "manipulator_ken", "ken", "none", 3.0)});
  list.push_back({"cube", "7.2.2", "10 cm cube on the manipulator trajectory",
                  make_run("cube", "manipulator_cube", "cube", "cube", 3.0)});
  list.push_back({"cylinder", "7.2.3", "cylinder on the manipulator trajectory",
                  make_run("cylinder", "manipulator_cylinder", "cylinder", "cylinder_z", 3.0)});
  {
    Experiment e{"correction", "7.3", "ken on the manipulator trajectory, code correction on",
                 make_run("correction", "manipulator_ken", "ken", "none", 3.0)};
    list.push_back(e);
    e.name = "correction_off";
    e.what = "the same run with code correction off (Algorithm 1 disabled)";
    e.run.scenario = "correction";
    e.run.code_correction = false;
    e.run.notes = "code correction OFF";
    list.push_back(e);
  }
  list.push_back({"init", "7.4", "initial alignment of the static ken",
                  make_run("init", "static_ken", "ken", "none", 0.5)});
  return list;
}

/// `correction` runs with its `correction_off` twin; `tracking` alone does not pull in
/// `no_tracking`.
std::vector<Experiment> select(const std::vector<std::string>& names) {
  const auto all = experiments();
  if (names.empty()) return all;
  std::vector<Experiment> chosen;
  for (const auto& name : names) {
    bool found = false;
    for (const auto& e : all) {
      if (e.name == name || (name == "correction" && e.name == "correction_off")) {
        chosen.push_back(e);
        found = true;
      }
    }
    if (!found) {
      std::string known;
      for (const auto& e : all) {
        if (e.name != "correction_off") known += (known.empty() ? "" : ", ") + e.name;
      }
      throw std::invalid_argument("unknown experiment '" + name + "' (known: " + known + ")");
    }
  }
  return chosen;
}

std::filesystem::path default_out_dir() {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  return std::filesystem::path("avs-runs") / (std::string("experiments-") + stamp);
}

}  // namespace

namespace {

void add_experiments_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "experiments",
      "Run the paper's Sec. 7 experiments on the simulated closed loop: tracking, no_tracking, "
      "ken, cube, cylinder, correction, init (all when none is named)");
  static std::vector<std::string> names;
  static bool json = false;
  static std::string out;
  static double time_scale = 1.0;
  static std::string calibration;
  static std::string true_calibration;
  static std::string profile = "ideal";
  static int seeds = 1;
  cmd->add_option("NAME", names, "experiments to run (default: all)");
  cmd->add_option("--profile", profile,
                  "simulated optics and sensor (docs/sim.md, sensor profiles): ideal (the "
                  "renderer of the published figures) or realistic (defocus, shot and read "
                  "noise, gloss, texture, flicker, motion blur)")
      ->check_member({"ideal", "realistic"})
      ->capture_default_str();
  cmd->add_option("--calibration", calibration,
                  "sensor calibration YAML (docs/decode.md) for the simulated sensor and the "
                  "decoder only; tracking, matching and the recorder take the camera model "
                  "from /depth/camera_info (default: the paper's sensor)")
      ->check_existing_file();
  cmd->add_option("--true-calibration", true_calibration,
                  "the simulated sensor's own calibration when it differs from --calibration: "
                  "the decoder gets --calibration (e.g. one recovered by avs calib solve), the "
                  "simulator this truth")
      ->check_existing_file();
  cmd->add_option("--seeds", seeds,
                  "run each scenario with sensor noise seeds 1..N (folders <out>/<name>/seed-<k>) "
                  "and report the median of each figure, with the smallest and largest")
      ->check_range(1, 20)
      ->capture_default_str();
  cmd->add_flag("--json", json, "print one JSON object keyed by scenario name on stdout");
  cmd->add_option("--out", out, "folder for the run folders (default avs-runs/experiments-<date>)");
  cmd->add_option("--time-scale", time_scale,
                  "multiply every scenario's simulated duration (short smoke runs: 0.2)")
      ->check_range(0.01, 10.0)
      ->capture_default_str();
  cmd->callback([] {
    std::vector<Experiment> chosen;
    try {
      chosen = select(names);
    } catch (const std::exception& e) {
      std::cerr << "avs experiments: " << e.what() << "\n";
      exit_status() = 2;
      return;
    }
    // Absolute: the report runs gnuplot inside each run folder.
    const std::filesystem::path root =
        std::filesystem::absolute(out.empty() ? default_out_dir() : std::filesystem::path(out));
    std::vector<std::pair<std::string, report::Summary>> summaries;
    std::string markdown;
    int status = 0;
    for (auto& e : chosen) {
      if (interrupted_by_signal()) break;
      e.run.dir = root / e.name;
      e.run.duration_s *= time_scale;
      e.run.extra_args["sensor_profile"] = profile;
      if (profile != "ideal") {
        e.run.notes += (e.run.notes.empty() ? "" : "; ") + std::string("sensor profile ") + profile;
      }
      if (!calibration.empty()) {
        e.run.extra_args["calibration"] = std::filesystem::absolute(calibration).string();
        e.run.notes += (e.run.notes.empty() ? "" : "; ") + std::string("calibration ") +
                       std::filesystem::path(calibration).filename().string();
      }
      if (!true_calibration.empty()) {
        e.run.extra_args["true_calibration"] = std::filesystem::absolute(true_calibration).string();
        e.run.notes += (e.run.notes.empty() ? "" : "; ") + std::string("true calibration ") +
                       std::filesystem::path(true_calibration).filename().string();
      }
      std::cerr << "== " << e.name << " (Sec. " << e.section << "): " << e.what << "\n";
      // One run per seed; with one seed the run folder is <out>/<name> as before.
      std::vector<report::Summary> per_seed;
      std::filesystem::path index_dir = e.run.dir;
      for (int seed = 1; seed <= seeds && !interrupted_by_signal(); ++seed) {
        ClosedLoopRun run = e.run;
        if (seeds > 1) {
          run.dir = e.run.dir / ("seed-" + std::to_string(seed));
          run.extra_args["seed"] = std::to_string(seed);
          run.notes +=
              (run.notes.empty() ? "" : "; ") + std::string("seed ") + std::to_string(seed);
          std::cerr << "== " << e.name << ": seed " << seed << " of " << seeds << "\n";
        }
        const ClosedLoopOutcome outcome = run_closed_loop(run, std::cerr);
        if (outcome.status != 0) status = outcome.status;
        try {
          const report::Report r = report::make_report(run.dir);
          for (const auto& failed : r.plots.failed) {
            std::cerr << "FAILED figure " << failed.png << ": " << failed.reason << "\n";
            status = 1;
          }
          per_seed.push_back(r.summary);
          if (seed == 1) index_dir = run.dir;
        } catch (const std::exception& ex) {
          std::cerr << "avs experiments: " << e.name << ": no report: " << ex.what() << "\n";
          status = 1;
        }
      }
      if (per_seed.empty()) continue;
      {
        const report::SeedSpread spread = report::across_seeds(per_seed);
        const report::Summary& summary = spread.median;
        const std::string seeds_note =
            seeds > 1 ? "median of " + std::to_string(per_seed.size()) + " seeds; " : "";
        const std::string table = report::format_comparison_table(e.run.scenario, summary);
        (json ? std::cerr : std::cout) << "\n"
                                       << e.name << " (Sec. " << e.section << ", " << seeds_note
                                       << index_dir.string() << "/index.html)\n"
                                       << table << report::format_run_clocks(summary) << "\n";
        if (seeds > 1) (json ? std::cerr : std::cout) << report::format_seed_spread(spread);
        (json ? std::cerr : std::cout) << "\n";
        markdown += "## " + e.name + " (Sec. " + e.section + ")\n\n" + e.what + ". " +
                    (seeds > 1 ? "Median of " + std::to_string(per_seed.size()) + " seeds. " : "") +
                    "Report: `" + (index_dir / "index.html").string() + "`.\n\n" +
                    report::format_comparison_markdown(e.run.scenario, summary) + "\n" +
                    (seeds > 1 ? report::format_seed_spread(spread, true) + "\n" : "") +
                    report::format_run_clocks(summary) + "\n\n";
        summaries.emplace_back(e.name, summary);
      }
    }
    const std::string json_text = report::experiments_json(summaries);
    std::ofstream(root / "experiments.json") << json_text << "\n";
    std::ofstream(root / "experiments.md") << markdown;
    if (json) std::cout << json_text << "\n";
    std::cerr << "experiments: " << root.string() << " (experiments.json, experiments.md)\n";
    if (interrupted_by_signal()) {
      std::cerr << "avs experiments: interrupted: the results above are partial\n";
      status = status == 0 ? 130 : status;
    }
    exit_status() = status;
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_experiments_command)

}  // namespace avs::cli
