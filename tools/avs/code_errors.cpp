// avs code-errors: Algorithm 1 (section 4.4, the code correction) against the simulator's
// ground truth (issue 19 item 2). The ken swings through the view with the head still, so that
// the code boundaries move over it while the rolling window mixes old and new bits; two rolling
// decoders see the same frames, one with the correction and one without. Per depth map: the
// fraction of the ken's pixels whose code is more than one code off the true code, and the
// depth error there. Writes code_errors.csv (per depth map) and code_errors.png (the map where
// the correction changed most codes: a figure like the paper's Fig. 21).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <string>
#include <vector>

#include "commands.hpp"

#if __has_include("avs/sim/code_error_study.hpp") && __has_include("avs/decode/png_io.hpp")
#include "avs/decode/png_io.hpp"
#include "avs/geometry/builtin_models.hpp"
#include "avs/sim/code_error_study.hpp"
#include "avs/sim/sensor_profile.hpp"
#define AVS_HAVE_CODE_ERRORS 1
#endif

namespace avs::cli {
namespace {

#ifdef AVS_HAVE_CODE_ERRORS
struct CodeErrorsOptions {
  std::string profile = "both";
  std::string axis = "lateral";
  double speed_mps = 1.0;
  double seconds = 1.0;
  std::string out = "avs-runs/code-errors";
  bool json = false;
};

sim::CodeErrorStudyConfig code_errors_config(const CodeErrorsOptions& o,
                                             sim::SensorProfile profile) {
  sim::CodeErrorStudyConfig c;
  sim::apply_sensor_profile(profile, c.simulator);
  sim::SceneObject ken;
  ken.name = "ken";
  ken.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("ken"));
  ken.albedo = 0.7;
  sim::LateralSwingConfig swing;
  swing.axis_world = o.axis == "vertical" ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  swing.amplitude_m = 0.1;  // stays in view of the still head at 1 m (the image is 0.8 m wide)
  swing.peak_speed_mps = o.speed_mps;
  ken.trajectory = std::make_shared<sim::LateralSwingTrajectory>(swing);
  c.scene.objects.push_back(ken);
  c.scene.objects.push_back(sim::make_background_plane(2.0));
  c.head =
      sim::at_rest(geometry::look_at(c.simulator.head, swing.T_world_object_centre.translation()));
  c.seconds = o.seconds;
  c.decoder.subcode_half_window = 4;  // as launch_config/closed_loop.yaml's decode
  c.object_index = 0;
  return c;
}

double code_errors_mean(const std::vector<sim::CodeErrorSample>& s,
                        double (*f)(const sim::CodeErrorSample&)) {
  double sum = 0;
  long n = 0;
  for (const auto& x : s) {
    const double v = f(x);
    if (std::isfinite(v)) sum += v, ++n;
  }
  return n > 0 ? sum / n : std::nan("");
}

/// Fig. 21's idea in grey levels, three panels around the ken (2x): its pixels more than one
/// code off without the correction (black on grey), with it, and the pixels whose code the
/// correction changed. White: no decoded code (or not the ken).
void write_code_errors_figure(const std::filesystem::path& path, const sim::CodeErrorStudy& s) {
  const int w = s.width, h = s.height, gap = 6, zoom = 2, margin = 12;
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!s.figure_on_object[static_cast<std::size_t>(y) * w + x]) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (x1 < 0) return;
  x0 = std::max(0, x0 - margin), y0 = std::max(0, y0 - margin);
  x1 = std::min(w - 1, x1 + margin), y1 = std::min(h - 1, y1 + margin);
  const int cw = (x1 - x0 + 1) * zoom, ch = (y1 - y0 + 1) * zoom;
  decode::GrayImage8 image;
  image.width = 3 * cw + 2 * gap;
  image.height = ch;
  image.pixels.assign(static_cast<std::size_t>(image.width) * ch, 255);
  for (int panel = 0; panel < 3; ++panel) {
    for (int y = 0; y < ch; ++y) {
      for (int x = 0; x < cw; ++x) {
        const std::size_t i = static_cast<std::size_t>(y0 + y / zoom) * w + (x0 + x / zoom);
        const int truth = s.figure_true_code[i];
        const int with = s.figure_corrected_code[i], without = s.figure_uncorrected_code[i];
        const int decoded = panel == 0 ? without : with;
        std::uint8_t v = 255;
        if (s.figure_on_object[i] && truth >= 0 && decoded >= 0) v = 190;
        bool mark = false;
        if (panel < 2) mark = v == 190 && std::abs(decoded - truth) > 1;
        if (panel == 2) mark = s.figure_on_object[i] && with != without;
        if (mark) v = 0;
        image.pixels[static_cast<std::size_t>(y) * image.width + panel * (cw + gap) + x] = v;
      }
    }
  }
  decode::write_png_gray8(path.string(), image);
}

int run_code_errors(const CodeErrorsOptions& o) {
  std::vector<sim::SensorProfile> profiles;
  if (o.profile != "realistic") profiles.push_back(sim::SensorProfile::kIdeal);
  if (o.profile != "ideal") profiles.push_back(sim::SensorProfile::kRealistic);
  std::filesystem::create_directories(o.out);
  std::string json = "{";
  std::printf("code-errors: ken swinging %s at %.2f m/s peak, head still, %.2f s, sub-code h 4\n",
              o.axis.c_str(), o.speed_mps, o.seconds);
  std::printf("%-10s %-11s %6s %11s %11s %13s %13s %11s\n", "profile", "correction", "maps",
              "off>1 mean", "off>1 max", "depth |err|", "depth RMS at", "depth RMS");
  std::printf("%-10s %-11s %6s %11s %11s %13s %13s %11s\n", "", "", "", "(% pixels)", "(% pixels)",
              "median at off", "off px (mm)", "all (mm)");
  for (const sim::SensorProfile profile : profiles) {
    std::cerr << "code-errors: rendering and decoding " << o.seconds << " s with the "
              << sim::to_string(profile) << " sensor...\n";
    const sim::CodeErrorStudy s = run_code_error_study(code_errors_config(o, profile));
    const std::string name = sim::to_string(profile);
    std::ofstream csv(std::filesystem::path(o.out) / ("code_errors_" + name + ".csv"));
    csv << "t_s,compared_px,off_corrected_px,off_uncorrected_px,depth_rms_off_corrected_mm,"
           "depth_rms_off_uncorrected_mm,depth_rms_corrected_mm,depth_rms_uncorrected_mm,"
           "moved_px\n";
    for (std::size_t k = 0; k < s.corrected.size(); ++k) {
      const auto& a = s.corrected[k];
      const auto& b = s.uncorrected[k];
      csv << a.t_s << ',' << a.compared << ',' << a.off_by_more << ',' << b.off_by_more << ','
          << a.depth_rms_off_mm << ',' << b.depth_rms_off_mm << ',' << a.depth_rms_mm << ','
          << b.depth_rms_mm << ',' << s.moved[k] << '\n';
    }
    if (!s.figure_true_code.empty()) {
      write_code_errors_figure(std::filesystem::path(o.out) / ("code_errors_" + name + ".png"), s);
    }
    json += std::string(json.size() > 1 ? ", " : "") + "\"" + name + "\": {";
    for (int corrected = 1; corrected >= 0; --corrected) {
      const auto& v = corrected ? s.corrected : s.uncorrected;
      const double off_mean =
          100 * code_errors_mean(v, [](const sim::CodeErrorSample& x) { return x.off_fraction(); });
      double off_max = 0;
      for (const auto& x : v) off_max = std::max(off_max, 100 * x.off_fraction());
      const double rms_off =
          code_errors_mean(v, [](const sim::CodeErrorSample& x) { return x.depth_rms_off_mm; });
      const double median_off =
          code_errors_mean(v, [](const sim::CodeErrorSample& x) { return x.depth_median_off_mm; });
      const double rms_all =
          code_errors_mean(v, [](const sim::CodeErrorSample& x) { return x.depth_rms_mm; });
      std::printf("%-10s %-11s %6zu %11.3f %11.3f %13.1f %13.1f %11.2f\n", name.c_str(),
                  corrected ? "on" : "off", v.size(), off_mean, off_max, median_off, rms_off,
                  rms_all);
      const std::string key = corrected ? "correction_on" : "correction_off";
      char buffer[256];
      std::snprintf(buffer, sizeof buffer,
                    "%s\"%s\": {\"off_by_more_than_one_percent_mean\": %.6g, "
                    "\"off_by_more_than_one_percent_max\": %.6g, \"depth_rms_at_off_mm\": %.6g, "
                    "\"depth_median_abs_at_off_mm\": %.6g, \"depth_rms_mm\": %.6g, "
                    "\"depth_maps\": %zu}",
                    corrected ? "" : ", ", key.c_str(), off_mean, off_max,
                    std::isfinite(rms_off) ? rms_off : -1.0,
                    std::isfinite(median_off) ? median_off : -1.0, rms_all, v.size());
      json += buffer;
    }
    const double moved_mean =
        s.moved.empty() ? 0.0
                        : std::accumulate(s.moved.begin(), s.moved.end(), 0.0) / s.moved.size();
    json += ", \"moved_px_mean\": " + std::to_string(moved_mean) + "}";
    std::printf("%-10s pixels whose code the correction changed: %.1f per map (mean)\n",
                name.c_str(), moved_mean);
  }
  json += "}";
  std::ofstream(std::filesystem::path(o.out) / "code_errors.json") << json << "\n";
  if (o.json) std::cout << json << "\n";
  std::cerr << "code-errors: " << o.out << " (code_errors_<profile>.csv, .png, code_errors.json)\n";
  return 0;
}
#endif

void add_code_errors_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "code-errors",
      "Algorithm 1 (code correction, Sec. 4.4) against the simulator's ground truth: the ken "
      "swinging past a still head, decoded with and without the correction");
#ifdef AVS_HAVE_CODE_ERRORS
  static CodeErrorsOptions o;
  cmd->add_option("--profile", o.profile, "sensor profile: ideal, realistic or both")
      ->check_member({"ideal", "realistic", "both"})
      ->capture_default_str();
  cmd->add_option("--axis", o.axis, "swing direction: lateral (world Y) or vertical (world Z)")
      ->check_member({"lateral", "vertical"})
      ->capture_default_str();
  cmd->add_option("--speed", o.speed_mps, "peak swing speed, m/s")
      ->check_range(0.01, 5.0)
      ->capture_default_str();
  cmd->add_option("--seconds", o.seconds, "simulated seconds per profile")
      ->check_range(0.05, 60.0)
      ->capture_default_str();
  cmd->add_option("--out", o.out, "folder for the CSV, PNG and JSON files")->capture_default_str();
  cmd->add_flag("--json", o.json, "print one JSON object (keys carry units) on stdout");
  cmd->callback([] { exit_status() = run_code_errors(o); });
#else
  cmd->callback([] {
    std::cerr << "avs code-errors: NOT AVAILABLE: this avs was built without the simulator\n";
    exit_status() = 1;
  });
#endif
}

}  // namespace

AVS_REGISTER_COMMAND(add_code_errors_command)

}  // namespace avs::cli
