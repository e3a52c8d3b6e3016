// `avs calib capture` then `avs calib solve` (issue 14): a simulated capture folder solves to a
// calibration file that the decoder's loader reads; a capture that fails a check is refused
// with its reason and no file is written; `avs calib bench --json` prints the issue's keys.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

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

TEST(CalibCommand, UnimplementedSourcesSaySo) {
  const fs::path out = fs::temp_directory_path() / ("avs-calib-src-" + std::to_string(getpid()));
  EXPECT_EQ(avs::testing::run_avs(
                {"calib", "capture", "--source", "bag", "--generate", "3", "--out", out.string()},
                out.string() + ".log", out.string() + ".err"),
            2);
  EXPECT_NE(avs::testing::read_file(out.string() + ".err").find("NOT IMPLEMENTED"),
            std::string::npos);
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

}  // namespace
