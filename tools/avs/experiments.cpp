// avs experiments [NAME...] [--json]: the paper's Sec. 7 as runnable scenarios on the simulated
// closed loop. Each scenario runs the graph anew (nothing is reused or hard-coded), writes its
// run folder with figures and index.html, and prints the paper's figures beside ours.
#include <ctime>
#include <fstream>
#include <iostream>
#include <optional>

#include "avs/report/paper.hpp"
#include "avs/report/profiles.hpp"
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
  {
    // Issue 19: what passes in front of the target must not take the head (the depth gate).
    Experiment e{"occlusion", "7.1.1",
                 "the swing with a 0.25 x 0.4 m board crossing 0.6 m in front of the head",
                 make_run("tracking", "swing_occluded", "ken", "none", 4.0)};
    e.run.extra_args["depth_gate_m"] = "0.15";
    e.run.notes = "tracking depth gate 0.15 m";
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

/// What the command line chose, for every scenario.
struct ExperimentOptions {
  std::vector<std::string> names;
  bool json = false;
  std::string out;
  double time_scale = 1.0;
  std::string calibration;
  std::string true_calibration;
  std::string profile = "realistic";
  int seeds = 1;
};

/// One scenario under one sensor profile, over the chosen seeds.
struct ScenarioResult {
  report::SeedSpread spread;        // spread.median is the scenario's figures
  std::filesystem::path index_dir;  // the first seed's run folder
};

std::optional<ScenarioResult> run_scenario(Experiment e, const std::string& profile,
                                           const std::filesystem::path& dir,
                                           const ExperimentOptions& o, int& status) {
  e.run.dir = dir;
  e.run.duration_s *= o.time_scale;
  e.run.extra_args["sensor_profile"] = profile;
  e.run.notes += (e.run.notes.empty() ? "" : "; ") + std::string("sensor profile ") + profile;
  if (!o.calibration.empty()) {
    e.run.extra_args["calibration"] = std::filesystem::absolute(o.calibration).string();
    e.run.notes += (e.run.notes.empty() ? "" : "; ") + std::string("calibration ") +
                   std::filesystem::path(o.calibration).filename().string();
  }
  if (!o.true_calibration.empty()) {
    e.run.extra_args["true_calibration"] = std::filesystem::absolute(o.true_calibration).string();
    e.run.notes += (e.run.notes.empty() ? "" : "; ") + std::string("true calibration ") +
                   std::filesystem::path(o.true_calibration).filename().string();
  }
  std::cerr << "== " << e.name << " (Sec. " << e.section << ", " << profile << "): " << e.what
            << "\n";
  // One run per seed; with one seed the run folder is `dir` itself.
  std::vector<report::Summary> per_seed;
  std::filesystem::path index_dir = e.run.dir;
  for (int seed = 1; seed <= o.seeds && !interrupted_by_signal(); ++seed) {
    ClosedLoopRun run = e.run;
    if (o.seeds > 1) {
      run.dir = e.run.dir / ("seed-" + std::to_string(seed));
      run.extra_args["seed"] = std::to_string(seed);
      run.notes += (run.notes.empty() ? "" : "; ") + std::string("seed ") + std::to_string(seed);
      std::cerr << "== " << e.name << ": seed " << seed << " of " << o.seeds << "\n";
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
  if (per_seed.empty()) return std::nullopt;
  return ScenarioResult{report::across_seeds(per_seed), index_dir};
}

void add_experiments_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "experiments",
      "Run the paper's Sec. 7 experiments on the simulated closed loop: tracking, no_tracking, "
      "occlusion, ken, cube, cylinder, correction, init (all when none is named)");
  static ExperimentOptions o;
  cmd->add_option("NAME", o.names, "experiments to run (default: all)");
  cmd->add_option("--profile", o.profile,
                  "simulated optics and sensor (docs/sim.md, sensor profiles): realistic "
                  "(defocus, shot and read noise, gloss, texture, flicker, motion blur), ideal "
                  "(the renderer of the earlier published figures), or both (each scenario "
                  "under each, folders <out>/<profile>/<name>, the figures side by side)")
      ->check_member({"realistic", "ideal", "both"})
      ->capture_default_str();
  cmd->add_option("--calibration", o.calibration,
                  "sensor calibration YAML (docs/decode.md) for the simulated sensor and the "
                  "decoder only; tracking, matching and the recorder take the camera model "
                  "from /depth/camera_info (default: the paper's sensor)")
      ->check_existing_file();
  cmd->add_option("--true-calibration", o.true_calibration,
                  "the simulated sensor's own calibration when it differs from --calibration: "
                  "the decoder gets --calibration (e.g. one recovered by avs calib solve), the "
                  "simulator this truth")
      ->check_existing_file();
  cmd->add_option("--seeds", o.seeds,
                  "run each scenario with sensor noise seeds 1..N (folders <out>/<name>/seed-<k>) "
                  "and report the median of each figure, with the smallest and largest")
      ->check_range(1, 20)
      ->capture_default_str();
  cmd->add_flag("--json", o.json,
                "print one JSON object keyed by scenario name on stdout (with --profile both: "
                "keyed by profile, then scenario)");
  cmd->add_option("--out", o.out,
                  "folder for the run folders (default avs-runs/experiments-<date>)");
  cmd->add_option("--time-scale", o.time_scale,
                  "multiply every scenario's simulated duration (short smoke runs: 0.2)")
      ->check_range(0.01, 10.0)
      ->capture_default_str();
  cmd->callback([] {
    std::vector<Experiment> chosen;
    try {
      chosen = select(o.names);
    } catch (const std::exception& e) {
      std::cerr << "avs experiments: " << e.what() << "\n";
      exit_status() = 2;
      return;
    }
    const std::vector<std::string> profiles = o.profile == "both"
                                                  ? std::vector<std::string>{"realistic", "ideal"}
                                                  : std::vector<std::string>{o.profile};
    const bool side_by_side = profiles.size() > 1;
    std::ostream& tables = o.json ? std::cerr : std::cout;
    // Absolute: the report runs gnuplot inside each run folder.
    const std::filesystem::path root =
        std::filesystem::absolute(o.out.empty() ? default_out_dir() : std::filesystem::path(o.out));
    // Per profile, in `profiles` order: each scenario's figures (median over the seeds).
    std::vector<std::vector<std::pair<std::string, report::Summary>>> summaries(profiles.size());
    std::string markdown;
    int status = 0;
    const std::string seeds_note =
        o.seeds > 1 ? "median of " + std::to_string(o.seeds) + " seeds; " : "";
    for (const auto& e : chosen) {
      if (interrupted_by_signal()) break;
      std::vector<report::ProfileSummary> per_profile;
      std::string reports;     // the run folders, for the side-by-side heading
      std::string profile_md;  // per profile: clocks and spread, under the side-by-side table
      for (std::size_t k = 0; k < profiles.size() && !interrupted_by_signal(); ++k) {
        const std::string& profile = profiles[k];
        const auto result = run_scenario(
            e, profile, side_by_side ? root / profile / e.name : root / e.name, o, status);
        if (!result) continue;
        const report::Summary& summary = result->spread.median;
        const std::string index = (result->index_dir / "index.html").string();
        tables << "\n"
               << e.name << " (Sec. " << e.section << ", " << profile << " sensor, " << seeds_note
               << index << ")\n"
               << report::format_comparison_table(e.run.scenario, summary)
               << report::format_run_clocks(summary) << "\n";
        if (o.seeds > 1) tables << report::format_seed_spread(result->spread);
        tables << "\n";
        const std::string spread_md =
            o.seeds > 1 ? report::format_seed_spread(result->spread, true) + "\n" : "";
        if (side_by_side) {
          reports += (reports.empty() ? "" : ", ") + profile + ": `" + index + "`";
          profile_md +=
              "**" + profile + "**: " + report::format_run_clocks(summary) + "\n\n" + spread_md;
        } else {
          markdown += "## " + e.name + " (Sec. " + e.section + ")\n\n" + e.what + ". " +
                      (o.seeds > 1 ? "Median of " + std::to_string(o.seeds) + " seeds. " : "") +
                      "Report: `" + index + "`.\n\n" +
                      report::format_comparison_markdown(e.run.scenario, summary) + "\n" +
                      spread_md + report::format_run_clocks(summary) + "\n\n";
        }
        per_profile.emplace_back(profile, summary);
        summaries[k].emplace_back(e.name, summary);
      }
      if (side_by_side && !per_profile.empty()) {
        tables << e.name << " (Sec. " << e.section << "), " << seeds_note
               << "the sensor profiles side by side\n"
               << report::format_profiles_side_by_side(e.run.scenario, per_profile) << "\n";
        markdown += "## " + e.name + " (Sec. " + e.section + ")\n\n" + e.what + ". " +
                    (o.seeds > 1 ? "Median of " + std::to_string(o.seeds) + " seeds. " : "") +
                    "Reports: " + reports + ".\n\n" +
                    report::format_profiles_side_by_side(e.run.scenario, per_profile, true) + "\n" +
                    profile_md;
      }
    }
    std::string json_text;
    if (side_by_side) {
      json_text = "{";
      for (std::size_t k = 0; k < profiles.size(); ++k) {
        json_text +=
            (k > 0 ? ", \"" : "\"") + profiles[k] + "\": " + report::experiments_json(summaries[k]);
      }
      json_text += "}";
    } else {
      json_text = report::experiments_json(summaries.front());
    }
    std::ofstream(root / "experiments.json") << json_text << "\n";
    std::ofstream(root / "experiments.md") << markdown;
    if (o.json) std::cout << json_text << "\n";
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
