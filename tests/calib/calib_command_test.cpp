// `avs calib capture` then `avs calib solve` (issue 14): a simulated capture folder solves to a
// calibration file that the decoder's loader reads; a capture that fails a check is refused
// with its reason and no file is written; `avs calib bench --json` prints the issue's keys.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/calib/bench.hpp"
#include "avs/decode/calibration_yaml.hpp"
#include "avs_program.hpp"

namespace {

namespace fs = std::filesystem;

TEST(CalibCommand, CaptureThenSolveWritesALoadableCalibration) {
  const fs::path dir = fs::temp_directory_path() / ("avs-calib-cmd-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path log = dir / "log.txt", err = dir / "err.txt";
  ASSERT_EQ(avs::testing::run_avs({"calib", "capture", "--generate", "10", "--near", "0.55",
                                   "--far", "1.6", "--out", (dir / "capture").string()},
                                  log, err),
            0)
      << avs::testing::read_file(log) << avs::testing::read_file(err);
  const std::string capture_log = avs::testing::read_file(log);
  EXPECT_NE(capture_log.find("pose 10/10"), std::string::npos) << capture_log;
  EXPECT_NE(capture_log.find("board found in 10"), std::string::npos) << capture_log;

  const fs::path calibration = dir / "out" / "calibration.yaml";
  ASSERT_EQ(
      avs::testing::run_avs(
          {"calib", "solve", (dir / "capture").string(), "--out", calibration.string()}, log, err),
      0)
      << avs::testing::read_file(log) << avs::testing::read_file(err);
  const avs::decode::SensorGeometry g = avs::decode::load_sensor_geometry_yaml(calibration);
  const avs::decode::SensorGeometry truth = avs::calib::bench_truth_geometry();
  EXPECT_NEAR(g.camera.fx_px, truth.camera.fx_px, 0.01 * truth.camera.fx_px);
  EXPECT_NEAR(g.projector.fy_px, truth.projector.fy_px, 0.01 * truth.projector.fy_px);
  EXPECT_NEAR((g.t_projector_camera_m - truth.t_projector_camera_m).norm(), 0.0, 0.002);
  EXPECT_EQ(g.layout.code_count, truth.layout.code_count);
  EXPECT_TRUE(fs::exists(dir / "out" / "calibration_report" / "coverage_camera.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "calibration_report" / "view_errors.csv"));
  EXPECT_NE(avs::testing::read_file(dir / "out" / "calibration_report" / "corner_errors.csv")
                .find("view,corner,camera_x_px"),
            std::string::npos);

  // The same capture with a stricter rule is refused, with the reason, and writes nothing.
  const fs::path refused = dir / "refused.yaml";
  EXPECT_EQ(avs::testing::run_avs({"calib", "solve", (dir / "capture").string(), "--min-views",
                                   "12", "--out", refused.string()},
                                  log, err),
            1);
  EXPECT_NE(avs::testing::read_file(err).find("too few usable views: 10 (need 12"),
            std::string::npos)
      << avs::testing::read_file(err);
  EXPECT_FALSE(fs::exists(refused));
  fs::remove_all(dir);
}

TEST(CalibCommand, AnUnknownSourceIsRefusedListingTheSources) {
  const fs::path out = fs::temp_directory_path() / ("avs-calib-src-" + std::to_string(getpid()));
  EXPECT_NE(avs::testing::run_avs({"calib", "capture", "--source", "tape", "--out", out.string()},
                                  out.string() + ".log", out.string() + ".err"),
            0);
  EXPECT_NE(avs::testing::read_file(out.string() + ".err").find("{sim,camera,bag}"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(out));
  fs::remove(out.string() + ".log");
  fs::remove(out.string() + ".err");
}

TEST(CalibCommand, BenchJsonHasTheIssueKeys) {
  const fs::path out = fs::temp_directory_path() / ("avs-calib-bench-" + std::to_string(getpid()));
  ASSERT_EQ(avs::testing::run_avs({"calib", "bench", "--json", "--views", "8"},
                                  out.string() + ".json", out.string() + ".err"),
            0)
      << avs::testing::read_file(out.string() + ".err");
  const std::string json = avs::testing::read_file(out.string() + ".json");
  for (const char* key : {"focal_error_pct", "baseline_error_mm", "rotation_error_deg",
                          "reprojection_rms_px", "plane_rms_ratio"}) {
    EXPECT_TRUE(std::isfinite(avs::testing::json_number(json, key))) << key << " in " << json;
  }
  fs::remove(out.string() + ".json");
  fs::remove(out.string() + ".err");
}

// Issue 14 section 4: the closed loop (`avs experiments ken`) decoding with a calibration that
// `avs calib solve` recovered from a simulated capture does as well as decoding with the true
// one, the simulator rendering with the truth (docs/calibration.md: the bench's sensor, whose
// truth itself misses the 2 deg orientation goal, so that goal is compared, not asserted).
TEST(CalibCommand, ClosedLoopWithTheRecoveredCalibrationDoesAsWellAsWithTheTruth) {
  const fs::path dir = fs::temp_directory_path() / ("avs-calib-loop-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path log = dir / "log.txt", err = dir / "err.txt";
  ASSERT_EQ(avs::testing::run_avs({"calib", "capture", "--generate", "16", "--near", "0.55",
                                   "--far", "1.6", "--out", (dir / "capture").string()},
                                  log, err),
            0)
      << avs::testing::read_file(err);
  const fs::path truth = dir / "capture" / "truth_calibration.yaml";
  const fs::path recovered = dir / "recovered.yaml";
  ASSERT_EQ(
      avs::testing::run_avs(
          {"calib", "solve", (dir / "capture").string(), "--out", recovered.string()}, log, err),
      0)
      << avs::testing::read_file(log) << avs::testing::read_file(err);
  const auto run_ken = [&](const std::vector<std::string>& calibration, const char* name) {
    std::vector<std::string> words = {"experiments", "ken",   "--profile",          "ideal",
                                      "--json",      "--out", (dir / name).string()};
    words.insert(words.end(), calibration.begin(), calibration.end());
    const fs::path json = dir / (std::string(name) + ".json");
    EXPECT_EQ(avs::testing::run_avs(words, json, err), 0) << avs::testing::read_file(err);
    return avs::testing::read_file(json);
  };
  const std::string with_truth = run_ken({"--calibration", truth.string()}, "truth");
  const std::string with_recovered = run_ken(
      {"--true-calibration", truth.string(), "--calibration", recovered.string()}, "recovered");
  const auto value = [](const std::string& json, const char* key) {
    return avs::testing::json_number(json, key);
  };
  const double truth_mm = value(with_truth, "position_error_mm_rms");
  const double truth_deg = value(with_truth, "orientation_error_deg_rms");
  const double recovered_mm = value(with_recovered, "position_error_mm_rms");
  const double recovered_deg = value(with_recovered, "orientation_error_deg_rms");
  std::printf(
      "ken, decoded with the true calibration: %.2f mm / %.2f deg, %g flips; with the "
      "recovered one: %.2f mm / %.2f deg, %g flips\n",
      truth_mm, truth_deg, value(with_truth, "flips"), recovered_mm, recovered_deg,
      value(with_recovered, "flips"));
  EXPECT_EQ(value(with_recovered, "flips"), 0);
  EXPECT_LE(recovered_mm, 3.0);
  EXPECT_NEAR(recovered_mm, truth_mm, 0.3);
  EXPECT_NEAR(recovered_deg, truth_deg, 0.15);
  fs::remove_all(dir);
}

}  // namespace
