// avs calib capture | solve | bench: projector-camera calibration (issue 14,
// docs/calibration.md). The work is done by components/calib (avs_calib_core, avs_calib_io);
// these are its command-line wrappers. Built with OpenCV only; without it `avs calib` says so.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dds_environment.hpp"
#include "flash_images.hpp"
#include "interrupts.hpp"

#if __has_include("avs/calib/capture_folder.hpp")
#include "avs/calib/bag_capture.hpp"
#include "avs/calib/bench.hpp"
#include "avs/calib/camera_capture.hpp"
#include "avs/calib/capture_folder.hpp"
#include "avs/calib/solve.hpp"
#include "avs/decode/calibration_yaml.hpp"
#include "avs/projector/dlpc350_emulator.hpp"
#include "avs/projector/hidapi_transport.hpp"
#define AVS_HAVE_CALIB 1
#endif

namespace avs::cli {
namespace {

struct CaptureOptions {
  std::string out;
  std::string source = "sim";
  std::string poses;
  int generate = 0;
  double near_m = 0.5;
  double far_m = 2.0;
  double max_tilt_deg = 30;
  unsigned long seed = 14;
  std::string calibration;
  double noise_dn = 2.0;
  int pixels_per_code = 4;
  // --source camera
  int views = 12;
  std::string camera;
  std::string trigger = "hardware";
  int rate_hz = 0;  ///< 0: camera 1000, bag: from the recording
  double exposure_us = 0;
  double gain = -1;
  int width = 512;
  int height = 512;
  std::string trigger_source = "Line0";
  std::string trigger_activation = "RisingEdge";
  int socket_buffer_bytes = 16000000;
  std::string projector = "hid";
  bool trigger_out_invert = false;
  std::string projector_serial;
  int first_flash_image = 1;
  double pose_timeout_s = 60;
  int squares_x = 10;
  int squares_y = 7;
  double square_mm = 30;
  double margin_mm = 30;
  // --source bag
  std::string bag;
  std::string topic = "/camera/image_raw";
  int domain = 0;
};

struct CalibPatternsOptions {
  std::string out;
  std::string calibration;
  int pixels_per_code = 4;
  int first_flash_image = 1;
};

struct SolveOptions {
  std::string capture;
  std::string out;
  std::string report;
  int min_views = 6;
  double max_camera_rms_px = 0.5;
  double max_projector_rms_px = 1.0;
  double min_coverage = 0.5;
};

struct BenchOptions {
  bool json = false;
  int views = 16;
  unsigned long seed = 14;
  double noise_dn = 2.0;
};

#ifdef AVS_HAVE_CALIB

namespace fs = std::filesystem;

/// What `avs calib capture` tells about the views as they come, and its verdict at the end:
/// whether the board was found, and how much of the camera image the corners reach (the checks
/// `avs calib solve` makes).
class CaptureTally {
 public:
  explicit CaptureTally(const calib::CaptureInfo& info) : info_(info) {}

  /// "board found, N corners" or "board NOT found in the white frame".
  std::string add(const calib::BoardView& view) {
    const std::vector<Eigen::Vector2d> c = calib::find_board_corners(view.frames[0], info_.board);
    ++views_;
    found_ += c.empty() ? 0 : 1;
    for (const Eigen::Vector2d& p : c) {
      const int i = std::clamp(static_cast<int>(p.x() * 4 / info_.camera_width), 0, 3);
      const int j = std::clamp(static_cast<int>(p.y() * 4 / info_.camera_height), 0, 3);
      reached_[j][i] = true;
    }
    return c.empty() ? "board NOT found in the white frame"
                     : "board found, " + std::to_string(c.size()) + " corners";
  }

  /// Prints the verdict; 0, or 3 when the capture is too little for a calibration.
  int finish(const fs::path& dir) const {
    int cells = 0;
    for (const auto& row : reached_) cells += static_cast<int>(std::count(row, row + 4, true));
    std::printf("captured %d poses to %s: board found in %d, camera coverage %d of 16 grid cells\n",
                views_, dir.string().c_str(), found_, cells);
    const calib::SolveConfig defaults;
    if (found_ < defaults.min_views || cells < defaults.min_coverage * 16) {
      std::printf(
          "WARNING: too little for a calibration (solve needs %d views with the board and "
          "%.0f %% coverage): add poses%s\n",
          defaults.min_views, 100 * defaults.min_coverage,
          cells < defaults.min_coverage * 16 ? " nearer the image corners" : "");
      return 3;
    }
    return 0;
  }

 private:
  const calib::CaptureInfo& info_;
  int views_ = 0;
  int found_ = 0;
  bool reached_[4][4] = {};
};

std::string pose_name(std::size_t v) {
  char name[32];
  std::snprintf(name, sizeof name, "pose_%03zu", v);
  return name;
}

int run_camera_capture(const CaptureOptions& o);
int run_bag_capture(const CaptureOptions& o);

int run_capture(const CaptureOptions& o) {
  if (o.source != "sim" && (!o.poses.empty() || o.generate > 0)) {
    std::cerr << "avs calib capture: --poses and --generate are for --source sim; the " << o.source
              << " source captures the poses the board is put in\n";
    return 2;
  }
  if (o.source == "camera") return run_camera_capture(o);
  if (o.source == "bag") return run_bag_capture(o);
  if (o.poses.empty() == (o.generate == 0)) {
    std::cerr << "avs calib capture: give either --poses FILE or --generate N\n";
    return 2;
  }
  sim::RendererConfig renderer;
  renderer.geometry = o.calibration.empty() ? calib::bench_truth_geometry()
                                            : decode::load_sensor_geometry_yaml(o.calibration);
  renderer.noise_sigma_dn = o.noise_dn;
  renderer.noise_seed = o.seed;
  calib::BoardPoses poses;
  if (!o.poses.empty()) {
    poses = calib::load_board_poses_yaml(o.poses);
  } else {
    poses.T_camera_board = calib::generate_board_poses(renderer.geometry, poses.board, o.generate,
                                                       o.near_m, o.far_m, o.max_tilt_deg, o.seed);
  }
  calib::SimCapture capture(renderer, poses.board, o.pixels_per_code);
  calib::CaptureIndex index{capture.info(), {}};
  const fs::path dir(o.out);
  CaptureTally tally(capture.info());
  const std::size_t n = poses.T_camera_board.size();
  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Isometry3d& T = poses.T_camera_board[v];
    const calib::PoseVisibility seen =
        calib::pose_visibility(renderer.geometry, poses.board, T, 0.0);
    const calib::BoardView view = capture.render(T, static_cast<int>(v), pose_name(v));
    calib::write_view_frames(dir, view, capture.info());
    index.views.push_back({view.name, view.T_camera_board_truth});
    calib::write_capture_index(dir, index);
    std::printf(
        "pose %zu/%zu %s: z %.2f m, corners in view %.0f %% camera / %.0f %% projector, %s\n",
        v + 1, n, view.name.c_str(), T.translation().z(), 100 * seen.camera, 100 * seen.projector,
        tally.add(view).c_str());
    std::fflush(stdout);
  }
  return tally.finish(dir);
}

/// The rig's nominal calibration (`--calibration`; default: the paper's sensor).
decode::SensorGeometry nominal_geometry(const std::string& file) {
  return file.empty() ? decode::default_sensor_geometry() : decode::load_sensor_geometry_yaml(file);
}

/// The capture's codes and the rig's depth layout from the rig's nominal calibration.
calib::CaptureInfo camera_capture_info(const CaptureOptions& o) {
  const decode::SensorGeometry nominal = nominal_geometry(o.calibration);
  calib::CaptureInfo info;
  info.source = "camera";
  info.board.squares_x = o.squares_x;
  info.board.squares_y = o.squares_y;
  info.board.square_m = o.square_mm / 1000;
  info.board.margin_m = o.margin_mm / 1000;
  if (const std::string why = info.board.problem(); !why.empty()) {
    throw std::runtime_error("board: " + why);
  }
  info.camera_width = o.width;
  info.camera_height = o.height;
  info.codes = calib::calibration_codes(nominal.projector.width, nominal.projector.height,
                                        o.pixels_per_code);
  info.depth_code_layout = nominal.layout;
  return info;
}

int run_camera_capture(const CaptureOptions& o) {
  const calib::CaptureInfo info = camera_capture_info(o);
  calib::CameraCaptureConfig config;
  config.camera.device_id = o.camera;
  config.camera.width = o.width;
  config.camera.height = o.height;
  config.camera.exposure_time_us = o.exposure_us;
  config.camera.gain = o.gain;
  // 200 patterns/s unless told: a calibration is not in a hurry, and a longer exposure is less
  // noisy (the depth rig's 1000 works too).
  const int rate_hz = o.rate_hz > 0 ? o.rate_hz : 200;
  config.camera.frame_rate_hz = rate_hz;
  config.camera.trigger_mode =
      o.trigger == "free_run" ? camera::TriggerMode::kFreeRun : camera::TriggerMode::kHardware;
  config.camera.trigger_source = o.trigger_source;
  config.camera.trigger_activation = o.trigger_activation;
  config.camera.socket_buffer_bytes = o.socket_buffer_bytes;
  // Ctrl-C ends the wait for a pose: the capture keeps the poses so far, the projector is
  // stopped and the camera closed on the way out.
  stop_on_interrupt();
  config.interrupted = [] { return stop_requested().load(); };
  config.view_timeout = std::chrono::milliseconds(static_cast<long>(o.pose_timeout_s * 1000));
  projector::TransportOpener opener;
  if (o.projector != "none") {
    projector::LinkConfig link;
    link.sequence = calib::calibration_sequence(info.codes, rate_hz, o.first_flash_image);
    link.sequence.trigger_out1.invert = o.trigger_out_invert;
    config.projector = link;
    if (o.projector == "emulator") {
      // No hardware: avs's DLPC350 emulator with the flash the sequence needs (for a dry run
      // against a simulated camera; nothing is projected).
      const int images =
          o.first_flash_image + (link.sequence.pattern_count + projector::kPatternsPerImage - 1) /
                                    projector::kPatternsPerImage;
      opener = projector::emulator_opener(std::make_shared<projector::Dlpc350Emulator>(
          projector::EmulatorConfig{.flash_image_count = images, .busy_reads = 1}));
    } else {
      std::printf(
          "WARNING: the USB HID path to a real LightCrafter 4500 (hidapi) is NOT exercised by "
          "avs's tests (no projector on the test machine; the DLPC350 protocol is tested "
          "against avs's emulator only)\n");
      opener = projector::hidapi_opener(
          {projector::kUsbVendorId, projector::kUsbProductId, o.projector_serial});
    }
  }
  if (config.camera.trigger_mode == camera::TriggerMode::kHardware) {
    std::printf(
        "WARNING: the camera's hardware trigger is NOT exercised by avs's tests (Aravis's fake "
        "camera only free-runs)\n");
  }
  std::printf(
      "calibration capture from the camera: %zu frames per pose (white x %zu, black, %d column "
      "and %d row bits +/-) at %d Hz; projector %s\n",
      calib::projection_sequence(info.codes).size(), calib::kWhiteFrames,
      info.codes.columns.bit_count, info.codes.rows.bit_count, rate_hz, o.projector.c_str());
  calib::CameraCapture capture(config, opener, info.codes, [](const std::string& line) {
    std::printf("  %s\n", line.c_str());
    std::fflush(stdout);
  });
  std::printf("%s\n", capture.description().c_str());
  const fs::path dir(o.out);
  calib::CaptureIndex index{info, {}};
  CaptureTally tally(index.info);
  std::vector<decode::GrayImage8> taken_whites;
  for (int v = 0; v < o.views; ++v) {
    std::printf(
        "pose %d/%d: put the board in a new pose and hold it still (taken when the view is "
        "new and still; %.0f s)\n",
        v + 1, o.views, o.pose_timeout_s);
    std::fflush(stdout);
    std::optional<calib::BoardView> view =
        capture.capture_view(pose_name(static_cast<std::size_t>(v)), taken_whites);
    if (!view) {
      std::printf("pose %d/%d: %s: capture ends with %d poses\n", v + 1, o.views,
                  stop_requested() ? "interrupted"
                                   : ("no new still view within " +
                                      std::to_string(static_cast<int>(o.pose_timeout_s)) + " s")
                                         .c_str(),
                  v);
      break;
    }
    calib::write_view_frames(dir, *view, index.info);
    index.views.push_back({view->name, std::nullopt});
    calib::write_capture_index(dir, index);
    std::printf("pose %d/%d %s captured: %s\n", v + 1, o.views, view->name.c_str(),
                tally.add(*view).c_str());
    std::fflush(stdout);
    taken_whites.push_back(view->frames[0]);
  }
  return tally.finish(dir);
}

int run_bag_capture(const CaptureOptions& o) {
  if (o.bag.empty()) {
    std::cerr << "avs calib capture: --source bag needs --bag FILE (a recording of " << o.topic
              << ", e.g. by launch_config/calib_record.yaml)\n";
    return 2;
  }
  calib::CaptureIndex index{camera_capture_info(o), {}};
  index.info.source = "bag";
  calib::BagCaptureConfig config;
  config.topic = o.topic;
  config.rate_hz = o.rate_hz;
  config.dds_domain = o.domain;
  const fs::path dir(o.out);
  std::optional<CaptureTally> tally;
  std::printf("calibration capture from %s (%s): every new still pose of the board\n",
              o.bag.c_str(), o.topic.c_str());
  const calib::BagCaptureStats stats = calib::capture_from_bag(
      o.bag, index.info.codes, config,
      [&](calib::BoardView&& view) {
        if (!tally) {
          // The camera's size is the recording's.
          index.info.camera_width = view.frames[0].width;
          index.info.camera_height = view.frames[0].height;
          tally.emplace(index.info);
        }
        view.name = pose_name(index.views.size());
        calib::write_view_frames(dir, view, index.info);
        index.views.push_back({view.name, std::nullopt});
        calib::write_capture_index(dir, index);
        std::printf("pose %zu %s captured: %s\n", index.views.size(), view.name.c_str(),
                    tally->add(view).c_str());
        std::fflush(stdout);
      },
      [](const std::string& line) {
        std::printf("  %s\n", line.c_str());
        std::fflush(stdout);
      });
  std::printf(
      "%lld messages: %lld views, %lld checked cycles of a pose already taken, %lld cycles "
      "refused, %lld frames off the %.3f ms period grid, %lld unusable images\n",
      static_cast<long long>(stats.messages), static_cast<long long>(stats.views),
      static_cast<long long>(stats.same_pose), static_cast<long long>(stats.rejected_cycles),
      static_cast<long long>(stats.off_grid), stats.period_ms,
      static_cast<long long>(stats.bad_images));
  if (!tally) {
    std::printf("no view found in %s: WARNING, nothing captured\n", o.bag.c_str());
    return 3;
  }
  return tally->finish(dir);
}

int run_calib_patterns(const CalibPatternsOptions& o) {
  const decode::SensorGeometry nominal = nominal_geometry(o.calibration);
  const calib::CaptureCodes codes = calib::calibration_codes(
      nominal.projector.width, nominal.projector.height, o.pixels_per_code);
  const fs::path dir(o.out);
  fs::create_directories(dir);
  std::vector<std::vector<std::uint8_t>> pixels;
  std::vector<std::string> labels;
  std::ofstream index(dir / "index.csv");
  index << "index,file,frame,width,height\n";
  const std::vector<calib::FrameId> sequence = calib::projection_sequence(codes);
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    const decode::GrayImage8 image = calib::projector_pattern(codes, sequence[k]);
    const std::string frame = sequence[k].label();
    char name[64];
    std::snprintf(name, sizeof name, "calib_%02zu_%s.png", k, frame.c_str());
    decode::write_png_gray8((dir / name).string(), image);
    index << k << ',' << name << ',' << frame << ',' << image.width << ',' << image.height << '\n';
    pixels.push_back(image.pixels);
    labels.push_back(frame);
  }
  index.close();
  const int images = write_flash_images(pixels, labels, "frame", codes.projector_width,
                                        codes.projector_height, o.first_flash_image, dir);
  if (!index || images < 0) {
    std::cerr << "avs calib patterns: cannot write to " << dir.string() << '\n';
    return 1;
  }
  std::printf(
      "wrote the calibration sequence: %zu patterns (%dx%d; white x %zu, black, %d column and %d "
      "row Gray-code bits +/-, %d DMD pixels per code) as PNG files with index.csv, and %d "
      "LightCrafter 4500 flash image(s) with lut.csv, first flash image index %d, to %s\n",
      sequence.size(), codes.projector_width, codes.projector_height, calib::kWhiteFrames,
      codes.columns.bit_count, codes.rows.bit_count, o.pixels_per_code, images, o.first_flash_image,
      dir.string().c_str());
  return 0;
}

void print_truth_errors(const decode::SensorGeometry& t, const decode::SensorGeometry& e) {
  std::printf(
      "against the simulator's truth: camera f %+.3f / %+.3f %%, c %+.2f / %+.2f px; "
      "projector f %+.3f / %+.3f %%, c %+.2f / %+.2f px; t %.3f mm off\n",
      100 * (e.camera.fx_px / t.camera.fx_px - 1), 100 * (e.camera.fy_px / t.camera.fy_px - 1),
      e.camera.cx_px - t.camera.cx_px, e.camera.cy_px - t.camera.cy_px,
      100 * (e.projector.fx_px / t.projector.fx_px - 1),
      100 * (e.projector.fy_px / t.projector.fy_px - 1), e.projector.cx_px - t.projector.cx_px,
      e.projector.cy_px - t.projector.cy_px,
      1000 * (e.t_projector_camera_m - t.t_projector_camera_m).norm());
}

int run_solve(const SolveOptions& o) {
  const fs::path dir(o.capture);
  const calib::CaptureIndex index = calib::read_capture_index(dir);
  std::vector<calib::ViewObservation> observations;
  for (std::size_t v = 0; v < index.views.size(); ++v) {
    const calib::BoardView view = calib::read_view(dir, index.views[v], index.info);
    observations.push_back(calib::observe_view(view, index.info));
    const calib::ViewObservation& obs = observations.back();
    std::printf("view %zu/%zu %s: %s\n", v + 1, index.views.size(), obs.name.c_str(),
                obs.board_found ? (std::to_string(obs.corners_with_projector()) + " of " +
                                   std::to_string(obs.corners.size()) + " corners with codes")
                                      .c_str()
                                : obs.problem.c_str());
    std::fflush(stdout);
  }
  calib::SolveConfig config;
  config.min_views = o.min_views;
  config.max_camera_rms_px = o.max_camera_rms_px;
  config.max_projector_rms_px = o.max_projector_rms_px;
  config.min_coverage = o.min_coverage;
  const calib::CalibrationResult result =
      calib::solve_calibration(index.info, observations, config);
  const std::string summary = calib::summary_text(result);
  std::cout << summary;
  if (index.info.truth && result.views_used >= 3)
    print_truth_errors(*index.info.truth, result.geometry);
  const fs::path report =
      o.report.empty() ? fs::path(o.out).parent_path() / "calibration_report" : fs::path(o.report);
  fs::create_directories(report);
  std::ofstream(report / "summary.txt") << summary;
  std::ofstream views(report / "view_errors.csv");
  views << "view,used,corners,camera_rms_px,projector_rms_px,why_not\n";
  for (const calib::ViewReport& v : result.views) {
    views << v.name << ',' << (v.used ? 1 : 0) << ',' << v.corners << ',' << v.camera_rms_px << ','
          << v.projector_rms_px << ",\"" << v.why_not << "\"\n";
  }
  std::ofstream(report / "corner_errors.csv") << calib::corner_errors_csv(result);
  if (result.views_used > 0) {
    decode::write_png_gray8((report / "coverage_camera.png").string(),
                            calib::coverage_image(index.info, observations, result, false));
    decode::write_png_gray8((report / "coverage_projector.png").string(),
                            calib::coverage_image(index.info, observations, result, true));
  }
  std::printf("report (summary.txt, view_errors.csv, corner_errors.csv, coverage_*.png) in %s\n",
              report.string().c_str());
  if (!result.accepted) {
    std::cerr << "avs calib solve: calibration refused, " << o.out << " not written:\n";
    for (const std::string& why : result.refusals) std::cerr << "  " << why << '\n';
    return 1;
  }
  if (!fs::path(o.out).parent_path().empty()) fs::create_directories(fs::path(o.out).parent_path());
  std::ofstream file(o.out);
  file << "# Calibration from avs calib solve " << o.capture << " (" << result.views_used
       << " views, reprojection RMS camera " << result.camera_rms_px << " px, projector "
       << result.projector_rms_px << " px)\n"
       << decode::sensor_geometry_to_yaml(result.geometry);
  if (!file) {
    std::cerr << "avs calib solve: cannot write " << o.out << '\n';
    return 1;
  }
  // Read back through the loader that decode, tracking and matching use.
  decode::load_sensor_geometry_yaml(o.out);
  std::printf("wrote %s (load it with --calibration or a component's calibration_file)\n",
              o.out.c_str());
  return 0;
}

int run_bench(const BenchOptions& o) {
  calib::BenchConfig config;
  config.views = o.views;
  config.seed = o.seed;
  config.noise_sigma_dn = o.noise_dn;
  const calib::BenchResult r = calib::run_calibration_bench(config, o.json ? nullptr : stdout);
  const calib::CalibrationResult& c = r.calibration;
  if (o.json) {
    std::printf(
        "{\"accepted\": %s, \"views\": %d, \"views_used\": %d, \"focal_error_pct\": %.6g, "
        "\"principal_point_error_px\": %.6g, \"distortion_error_px\": %.6g, "
        "\"baseline_error_mm\": %.6g, \"rotation_error_deg\": %.6g, \"reprojection_rms_px\": "
        "%.6g, \"camera_reprojection_rms_px\": %.6g, \"projector_reprojection_rms_px\": %.6g, "
        "\"plane_rms_true_mm\": %.6g, \"plane_rms_recovered_mm\": %.6g, \"plane_rms_ratio\": "
        "%.6g}\n",
        c.accepted ? "true" : "false", o.views, c.views_used, r.focal_error_pct,
        r.principal_point_error_px, r.distortion_error_px, r.baseline_error_mm,
        r.rotation_error_deg, c.stereo_rms_px, c.camera_rms_px, c.projector_rms_px,
        r.plane_rms_true_mm, r.plane_rms_recovered_mm, r.plane_rms_ratio);
  } else {
    std::cout << calib::summary_text(c);
    std::printf(
        "focal error %.3f %%, principal point %.2f px, distortion %.2f px, baseline %.3f "
        "mm, rotation %.4f deg, plane depth RMS %.2f / %.2f mm = %.3f\n",
        r.focal_error_pct, r.principal_point_error_px, r.distortion_error_px, r.baseline_error_mm,
        r.rotation_error_deg, r.plane_rms_recovered_mm, r.plane_rms_true_mm, r.plane_rms_ratio);
  }
  return c.accepted ? 0 : 1;
}

template <typename Fn>
void guarded(const char* name, Fn run) {
  try {
    exit_status() = run();
  } catch (const std::exception& e) {
    std::cerr << "avs calib " << name << ": " << e.what() << '\n';
    exit_status() = 1;
  }
}

#else

template <typename Fn>
void guarded(const char* name, Fn) {
  std::cerr << "avs calib " << name
            << ": NOT AVAILABLE: this avs was built without OpenCV (calib3d); install "
               "libopencv-dev (bash tools/run.sh test does) and rebuild\n";
  exit_status() = 1;
}
int run_capture(const CaptureOptions&) {
  return 1;
}
int run_solve(const SolveOptions&) {
  return 1;
}
int run_bench(const BenchOptions&) {
  return 1;
}
int run_calib_patterns(const CalibPatternsOptions&) {
  return 1;
}

#endif

void add_calib_command(Command& app) {
  auto* calib = app.add_subcommand(
      "calib", "Projector-camera calibration: capture board views, solve, check (issue 14)");
  calib->require_subcommand(1);

  static CaptureOptions c;
  auto* capture = calib->add_subcommand(
      "capture",
      "Capture board views (white, black, column and row Gray codes, positive and negative) "
      "into a capture folder (PNG per frame + index.yaml); sources: the simulator, or the rig's "
      "camera and projector");
  capture->add_option("--out", c.out, "capture folder (created)")->required();
  capture
      ->add_option("--source", c.source,
                   "sim (the simulator), camera (the rig: a GenICam camera through Aravis, "
                   "the projector looping the calibration sequence) or bag (a recording of "
                   "the rig's camera during a calibration session)")
      ->capture_default_str()
      ->check_member({"sim", "camera", "bag"});
  capture->add_option("--poses", c.poses, "board-pose YAML (board and a list of poses)")
      ->check_existing_file();
  capture->add_option("--generate", c.generate, "or: a seeded spread of N board poses")
      ->check_range(1, 10000);
  capture->add_option("--near", c.near_m, "nearest board distance for --generate, m")
      ->capture_default_str()
      ->check_range(0.05, 100);
  capture->add_option("--far", c.far_m, "farthest board distance for --generate, m")
      ->capture_default_str()
      ->check_range(0.05, 100);
  capture->add_option("--max-tilt", c.max_tilt_deg, "board tilt for --generate, deg")
      ->capture_default_str()
      ->check_range(0, 80);
  capture->add_option("--seed", c.seed, "poses and sensor noise seed")
      ->capture_default_str()
      ->check_range(0, 4294967295.0);
  capture
      ->add_option("--calibration", c.calibration,
                   "sim: the simulated rig's true calibration (default: the bench's sensor, "
                   "distortion on both lenses); camera and bag: the rig's nominal calibration "
                   "(projector size and depth code layout; default: the paper's)")
      ->check_existing_file();
  capture->add_option("--noise", c.noise_dn, "sensor noise sigma, DN")
      ->capture_default_str()
      ->check_range(0, 255);
  capture
      ->add_option("--pixels-per-code", c.pixels_per_code,
                   "DMD pixels per code stripe (camera and bag: the value avs calib patterns "
                   "wrote the flash images with)")
      ->capture_default_str()
      ->check_range(1, 64);
  capture->add_option("--views", c.views, "camera: board poses to capture")
      ->capture_default_str()
      ->check_range(1, 1000);
  capture->add_option("--camera", c.camera,
                      "camera: Aravis id, serial or IP (empty: the only one)");
  capture
      ->add_option("--trigger", c.trigger,
                   "camera: hardware (the projector's trigger out) or free_run")
      ->capture_default_str()
      ->check_member({"hardware", "free_run"});
  capture
      ->add_option("--rate", c.rate_hz,
                   "camera and bag: patterns per second (camera: default 200; bag: default "
                   "from the recording's stamps)")
      ->check_range(1, 4000);
  capture->add_option("--exposure-us", c.exposure_us, "camera: ExposureTime (0: leave it)")
      ->capture_default_str()
      ->check_range(0, 1e7);
  capture->add_option("--gain", c.gain, "camera: Gain (-1: leave it)")
      ->capture_default_str()
      ->check_range(-1, 1000);
  capture->add_option("--width", c.width, "camera: ROI width, px")
      ->capture_default_str()
      ->check_range(16, 16384);
  capture->add_option("--height", c.height, "camera: ROI height, px")
      ->capture_default_str()
      ->check_range(16, 16384);
  capture
      ->add_option("--trigger-source", c.trigger_source,
                   "camera: the input wired to the projector's trigger out")
      ->capture_default_str();
  capture
      ->add_option("--trigger-activation", c.trigger_activation,
                   "camera: RisingEdge for an active-high trigger out")
      ->capture_default_str();
  capture
      ->add_option("--socket-buffer-bytes", c.socket_buffer_bytes,
                   "camera: GigE Vision receive buffer (net.core.rmem_max at least this)")
      ->capture_default_str()
      ->check_range(0, 1e9);
  capture->add_flag("--trigger-out-invert", c.trigger_out_invert,
                    "camera: the projector's TRIG_OUT_1 active low");
  capture
      ->add_option("--projector", c.projector,
                   "camera: hid (the LightCrafter 4500 over USB), emulator (avs's DLPC350 "
                   "emulator: a dry run, nothing projected) or none (it already loops the "
                   "calibration sequence)")
      ->capture_default_str()
      ->check_member({"hid", "emulator", "none"});
  capture->add_option("--projector-serial", c.projector_serial,
                      "camera: USB serial (empty: the first)");
  capture
      ->add_option("--first-flash-image", c.first_flash_image,
                   "camera: flash index of the calibration sequence's first image "
                   "(avs calib patterns)")
      ->capture_default_str()
      ->check_range(0, 255);
  capture
      ->add_option("--pose-timeout", c.pose_timeout_s,
                   "camera: seconds to wait for each new still pose")
      ->capture_default_str()
      ->check_range(0.1, 3600);
  capture->add_option("--squares-x", c.squares_x, "camera and bag: board squares along x")
      ->capture_default_str()
      ->check_range(3, 100);
  capture->add_option("--squares-y", c.squares_y, "camera and bag: board squares along y")
      ->capture_default_str()
      ->check_range(3, 100);
  capture->add_option("--square-mm", c.square_mm, "camera and bag: board square size, mm")
      ->capture_default_str()
      ->check_range(1, 1000);
  capture
      ->add_option("--margin-mm", c.margin_mm,
                   "camera and bag: light border around the squares, mm")
      ->capture_default_str()
      ->check_range(0, 1000);
  capture->add_option("--bag", c.bag, "bag: the recording (MCAP)")->check_existing_file();
  capture
      ->add_option("--topic", c.topic, "bag: the camera's image topic (sensor_msgs/Image, mono8)")
      ->capture_default_str();
  add_domain_option(capture, c.domain);
  capture->callback([] { guarded("capture", [] { return run_capture(c); }); });

  static CalibPatternsOptions p;
  auto* patterns = calib->add_subcommand(
      "patterns",
      "Write the calibration sequence the projector loops during `capture --source camera` "
      "(white x 3, black, column and row Gray codes +/-) as PNG files with index.csv, and the "
      "LightCrafter 4500's flash images with lut.csv");
  patterns->add_option("--out", p.out, "output folder (created)")->required();
  patterns
      ->add_option("--calibration", p.calibration,
                   "the rig's nominal calibration (projector size; default: the paper's)")
      ->check_existing_file();
  patterns->add_option("--pixels-per-code", p.pixels_per_code, "DMD pixels per code stripe")
      ->capture_default_str()
      ->check_range(1, 64);
  patterns
      ->add_option("--first-flash-image", p.first_flash_image,
                   "flash index of the first image (0 holds the depth sequence of avs patterns)")
      ->capture_default_str()
      ->check_range(0, 255);
  patterns->callback([] { guarded("patterns", [] { return run_calib_patterns(p); }); });

  static SolveOptions s;
  auto* solve = calib->add_subcommand(
      "solve",
      "Calibrate from a capture folder: corners, projector coordinates (local homographies), "
      "camera/projector/stereo calibration; writes the calibration YAML only if every check "
      "passes");
  solve->add_option("capture", s.capture, "capture folder")->required();
  solve->add_option("--out", s.out, "calibration YAML to write")->required();
  solve->add_option("--report", s.report,
                    "report folder (default: calibration_report beside --out)");
  solve->add_option("--min-views", s.min_views, "refuse with fewer usable views")
      ->capture_default_str()
      ->check_range(1, 10000);
  solve->add_option("--max-camera-rms", s.max_camera_rms_px, "refuse above, px")
      ->capture_default_str()
      ->check_range(0.001, 1000);
  solve->add_option("--max-projector-rms", s.max_projector_rms_px, "refuse above, px")
      ->capture_default_str()
      ->check_range(0.001, 1000);
  solve
      ->add_option("--min-coverage", s.min_coverage,
                   "refuse below this fraction of a 4x4 grid reached by corners")
      ->capture_default_str()
      ->check_range(0, 1);
  solve->callback([] { guarded("solve", [] { return run_solve(s); }); });

  static BenchOptions b;
  auto* bench = calib->add_subcommand(
      "bench",
      "Accuracy against simulator ground truth: seeded captures, solve, errors of the result "
      "and the depth RMS of a plane decoded with it");
  bench->add_flag("--json", b.json, "print one JSON object");
  bench->add_option("--views", b.views, "board poses")
      ->capture_default_str()
      ->check_range(1, 10000);
  bench->add_option("--seed", b.seed, "poses and noise seed")
      ->capture_default_str()
      ->check_range(0, 4294967295.0);
  bench->add_option("--noise", b.noise_dn, "sensor noise sigma, DN")
      ->capture_default_str()
      ->check_range(0, 255);
  bench->callback([] { guarded("bench", [] { return run_bench(b); }); });
}

}  // namespace

AVS_REGISTER_COMMAND(add_calib_command)

}  // namespace avs::cli
