// Issue 5's closed loop: the ken swung laterally at 1 m/s peak, 1 m in front of the sensor,
// through the real chain (sim_scene -> decode -> tracking -> servo_drive over Modbus TCP ->
// sim_amplifier -> head). With tracking the target stays in view the whole run and its image
// centroid stays near the centre; with the head held still the target leaves the view (the
// paper's Figures 9 and 11). Figures come from `avs experiments --json` of this very run.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "avs_program.hpp"

namespace fs = std::filesystem;

namespace {

using avs::testing::read_file;

/// The number for `key` inside the object of `scenario` in the experiments JSON.
double figure(const std::string& json, const std::string& scenario, const std::string& key) {
  const auto start = json.find("\"" + scenario + "\": {");
  if (start == std::string::npos) throw std::runtime_error("no scenario " + scenario);
  const auto end = json.find('}', start);
  return avs::testing::json_number(json.substr(start, end - start), key);
}

TEST(ClosedLoop, TrackingKeepsTheSwingingTargetInViewAndHoldingStillLosesIt) {
  const fs::path dir =
      fs::temp_directory_path() / ("avs-tracking-test-" + std::to_string(getpid()));
  fs::remove_all(dir);
  const std::string json_file = dir.string() + ".json";
  const int status = avs::testing::run_avs({"experiments", "tracking", "no_tracking", "--profile",
                                            "ideal", "--json", "--out", dir.string()},
                                           json_file, dir.string() + ".log");
  const std::string json = read_file(json_file);
  ASSERT_EQ(status, 0) << json << read_file(dir.string() + ".log");

  const double on_in_view = figure(json, "tracking", "in_view_fraction");
  const double on_rms = figure(json, "tracking", "centroid_error_px_rms");
  const double off_in_view = figure(json, "no_tracking", "in_view_fraction");
  const double off_rms = figure(json, "no_tracking", "centroid_error_px_rms");
  std::cout << "tracking on:  in view " << on_in_view << ", centroid error RMS " << on_rms
            << " px\ntracking off: in view " << off_in_view << ", centroid error RMS " << off_rms
            << " px\n";
  EXPECT_EQ(on_in_view, 1.0) << "the target left the view with tracking on";
  EXPECT_LE(on_rms, 20.0) << "issue 5 goal: centroid error RMS at most 20 px at 1 m/s";
  EXPECT_LT(off_in_view, 0.9) << "without tracking the swing must take the target out of view";
  EXPECT_GT(figure(json, "tracking", "depth_rate_hz"), 495.0);
  fs::remove_all(dir);
  fs::remove(json_file);
  fs::remove(dir.string() + ".log");
}

// Issue 19, occlusion: a 0.25 x 0.4 m board crosses 0.6 m in front of the head, inside Eq. 8's
// window, while the ken swings (launch_config/scenes/swing_occluded.yaml). With the paper's fixed
// window the board joins the mask and the head turns to it: the ken is in view for 47 % of the
// run (`avs launch launch_config/closed_loop.yaml scene:=swing_occluded depth_gate_m:=0 ...`).
// With the depth gate of closed_loop.yaml the head holds while the ken is hidden (0.4 s) and
// follows it again when it comes out: in view the whole run.
TEST(ClosedLoop, TrackingKeepsTheKenNotThePassingBoardInView) {
  const fs::path dir =
      fs::temp_directory_path() / ("avs-occlusion-test-" + std::to_string(getpid()));
  fs::remove_all(dir);
  const std::string json_file = dir.string() + ".json";
  const int status = avs::testing::run_avs(
      {"experiments", "occlusion", "--profile", "ideal", "--json", "--out", dir.string()},
      json_file, dir.string() + ".log");
  const std::string json = read_file(json_file);
  ASSERT_EQ(status, 0) << json << read_file(dir.string() + ".log");
  const double in_view = figure(json, "occlusion", "in_view_fraction");
  const double rms = figure(json, "occlusion", "centroid_error_px_rms");
  std::cout << "board crossing: in view " << in_view << ", centroid error RMS " << rms << " px\n";
  EXPECT_EQ(in_view, 1.0) << "the head followed the board, or lost the ken";
  // 19.9 px when measured (the head holds still while the ken is hidden); without occlusion the
  // goal is 20 px at 1 m/s.
  EXPECT_LE(rms, 25.0);
  fs::remove_all(dir);
  fs::remove(json_file);
  fs::remove(dir.string() + ".log");
}

}  // namespace
