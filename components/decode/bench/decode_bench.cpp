// `avs bench decode`: one rolling 1-bit update + triangulation of 512 x 512 (ours) beside the
// per-pixel Eq. 4 solve and OpenCV 4.6 structured_light::GrayCodePattern + cv::triangulatePoints,
// all on frames of the same synthesised scene (plane at 1.0 m), measured in the same run.
// OpenCV's headers stay in this file.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/structured_light.hpp>

#include "../src/rolling_kernel.hpp"
#include "../src/subcode.hpp"
#include "avs/bench/report.hpp"
#include "avs/decode/rolling_decoder.hpp"
#include "avs/decode/synthetic_plane.hpp"

namespace avs::decode {
namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

template <typename F>
double time_ms(F&& f) {
  const auto start = Clock::now();
  f();
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct RollingTiming {
  double push_frames_ms = 0;  ///< two push_frame calls (the positive copied), median
  double push_pair_ms = 0;    ///< one push_pair call, median
  double rms_error_m = 0;
};

RollingTiming time_rolling(const DecoderConfig& config, const SyntheticScene& scene, int updates) {
  RollingDecoder decoder(config);
  const int n = config.geometry.layout.bit_count;
  std::int64_t cycle = 0;
  for (int k = 0; k < n; ++k) {  // fill the window
    decoder.push_pair(scene.frame(k, Polarity::kPositive, 0).image,
                      scene.frame(k, Polarity::kNegative, 0).image, k, 0);
  }
  std::vector<double> frames_ms, pair_ms;
  for (int u = 0; u < 2 * updates; ++u) {
    const int k = u % n;
    if (k == 0) ++cycle;
    const PatternFrame positive = scene.frame(k, Polarity::kPositive, cycle);
    const PatternFrame negative = scene.frame(k, Polarity::kNegative, cycle);
    if (u % 2 == 0) {
      frames_ms.push_back(time_ms([&] {
        decoder.push_frame(positive);
        decoder.push_frame(negative);
      }));
    } else {
      pair_ms.push_back(
          time_ms([&] { decoder.push_pair(positive.image, negative.image, k, cycle); }));
    }
  }
  RollingTiming t;
  t.push_frames_ms = median(frames_ms);
  t.push_pair_ms = median(pair_ms);
  const auto depth = decoder.push_frame(scene.frame(0, Polarity::kPositive, cycle + 1)).depth_m;
  double sum = 0;
  int valid = 0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    if (std::isnan(depth[i])) continue;
    sum += std::pow(depth[i] - scene.true_depth_m[i], 2);
    ++valid;
  }
  t.rms_error_m = std::sqrt(sum / std::max(valid, 1));
  return t;
}

// The plain update and the update with sub-code refinement timed in alternation on the same
// pairs (which one goes first alternates too), so that both medians see the same machine: on a
// shared host the separate timings above moved by tens of per cent between sections of a run.
struct InterleavedTiming {
  double plain_ms = 0;
  double subcode_ms = 0;
};

InterleavedTiming time_interleaved(const DecoderConfig& plain_config,
                                   const DecoderConfig& subcode_config, const SyntheticScene& scene,
                                   int updates) {
  RollingDecoder plain(plain_config);
  RollingDecoder subcode(subcode_config);
  const int n = plain_config.geometry.layout.bit_count;
  for (int k = 0; k < n; ++k) {  // fill both windows
    for (RollingDecoder* decoder : {&plain, &subcode}) {
      decoder->push_pair(scene.frame(k, Polarity::kPositive, 0).image,
                         scene.frame(k, Polarity::kNegative, 0).image, k, 0);
    }
  }
  std::vector<double> plain_ms, subcode_ms;
  std::int64_t cycle = 0;
  for (int u = 0; u < updates; ++u) {
    const int k = u % n;
    if (k == 0) ++cycle;
    const PatternFrame positive = scene.frame(k, Polarity::kPositive, cycle);
    const PatternFrame negative = scene.frame(k, Polarity::kNegative, cycle);
    const auto update = [&](RollingDecoder& decoder) {
      return time_ms([&] {
        decoder.push_frame(positive);
        decoder.push_frame(negative);
      });
    };
    if (u % 2 == 0) {
      plain_ms.push_back(update(plain));
      subcode_ms.push_back(update(subcode));
    } else {
      subcode_ms.push_back(update(subcode));
      plain_ms.push_back(update(plain));
    }
  }
  return {median(plain_ms), median(subcode_ms)};
}

// The three passes of the sub-code update timed apart (medians), on the codes of a full-cycle
// decode of the scene: Gray words to codes (as a pass of its own; the decoder has them from its
// update pass since 2026-12-07), the window's line fit, the sub-code plane look-up (row by row
// with the decoder's rays).
struct SubcodePasses {
  double gray_to_code_ms = 0;
  double window_ms = 0;
  double lookup_ms = 0;
};

SubcodePasses time_subcode_passes(const DecoderConfig& config, const SyntheticScene& scene,
                                  int updates) {
  const SensorGeometry& g = config.geometry;
  const int n = g.layout.bit_count;
  std::vector<PatternFrame> frames;
  for (int k = 0; k < n; ++k) {
    frames.push_back(scene.frame(k, Polarity::kPositive, 0));
    frames.push_back(scene.frame(k, Polarity::kNegative, 0));
  }
  const FullCycleResult decoded = decode_full_cycle(config, frames);
  const auto pixels = static_cast<int>(decoded.code.size());
  const auto full = static_cast<std::uint16_t>((1u << n) - 1u);
  std::vector<std::uint16_t> gray(decoded.code.size()), valid(decoded.code.size());
  for (std::size_t i = 0; i < decoded.code.size(); ++i) {
    const auto code = static_cast<std::uint16_t>(std::max(decoded.code[i], 0));
    gray[i] = static_cast<std::uint16_t>(code ^ (code >> 1));
    valid[i] = decoded.code[i] >= 0 ? full : 0;
  }
  const DepthTable table(g, config.subcode_steps);
  detail::SubcodeRefiner refiner({g.camera.width, g.camera.height, config.subcode_half_window,
                                  config.subcode_max_jump, g.layout.code_count});
  std::vector<std::int16_t> codes(decoded.code.size());
  std::vector<float> refined(decoded.code.size()), depth(decoded.code.size());
  const detail::SubcodePlanes planes{table.subcode_planes(), table.subcode_steps(),
                                     table.subcode_plane_count(), table.linear_subcode_planes()};
  std::vector<double> gray_ms, window_ms, lookup_ms;
  for (int u = 0; u < updates; ++u) {
    gray_ms.push_back(time_ms([&] {
      detail::codes_from_gray(gray.data(), valid.data(), full, g.layout.code_count, codes.data(),
                              pixels);
    }));
    window_ms.push_back(time_ms([&] { refiner.refine(codes.data(), refined.data()); }));
    lookup_ms.push_back(time_ms([&] {
      const int width = g.camera.width;
      for (int y = 0; y < g.camera.height; ++y) {
        const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(y) * width;
        if (table.column_ray_x() != nullptr) {
          detail::triangulate_subcode_row(refined.data() + offset, planes, table.column_ray_x(),
                                          table.row_ray_y()[y], config.min_depth_m,
                                          config.max_depth_m, depth.data() + offset, width);
        } else {
          detail::triangulate_subcode(refined.data() + offset, planes, table.ray_x() + offset,
                                      table.ray_y() + offset, config.min_depth_m,
                                      config.max_depth_m, depth.data() + offset, width);
        }
      }
    }));
  }
  return {median(gray_ms), median(window_ms), median(lookup_ms)};
}

// FNV-1a over the bytes of every depth map of three cycles: equal between two commits when
// their decoders give bit-identical maps (a speed change must not change a result).
std::uint64_t hash_depth_maps(const DecoderConfig& config, const SyntheticScene& scene) {
  RollingDecoder decoder(config);
  const int n = config.geometry.layout.bit_count;
  std::uint64_t hash = 14695981039346656037ull;
  for (int u = 0; u < 3 * n; ++u) {
    const int k = u % n;
    const std::int64_t cycle = u / n;
    decoder.push_frame(scene.frame(k, Polarity::kPositive, cycle));
    const auto depth = decoder.push_frame(scene.frame(k, Polarity::kNegative, cycle)).depth_m;
    const auto* bytes = reinterpret_cast<const unsigned char*>(depth.data());
    for (std::size_t i = 0; i < depth.size() * sizeof(float); ++i) {
      hash = (hash ^ bytes[i]) * 1099511628211ull;
    }
  }
  return hash;
}

struct OpenCvTiming {
  double decode_ms = 0;
  double triangulate_ms = 0;
  double rms_error_m = 0;
  int pattern_images = 0;
  int decoded_pixels = 0;
};

// OpenCV cannot decode rows only (create(1, H) crashes in getProjPixel): the smallest set it
// accepts is a 2-column x 265-row projector, 1 column bit + 9 row bits = 20 images. Its rows
// are our codes (4 projector rows each), its 2 columns the projector's two halves.
OpenCvTiming time_opencv(const SensorGeometry& g, const SyntheticScene& scene, int psi, int runs) {
  const int width = scene.width, height = scene.height;
  cv::structured_light::GrayCodePattern::Params params;
  params.width = 2;
  params.height = g.layout.code_count;
  const cv::Ptr<cv::structured_light::GrayCodePattern> gray =
      cv::structured_light::GrayCodePattern::create(params);
  gray->setWhiteThreshold(static_cast<std::size_t>(psi));
  std::vector<cv::Mat> patterns;
  gray->generate(patterns);
  // Render what the camera sees of each OpenCV pattern (same noise model as render_plane).
  std::mt19937 random(99);
  std::normal_distribution<double> noise(0.0, 2.0);
  std::vector<cv::Mat> captured;
  for (const cv::Mat& pattern : patterns) {
    cv::Mat image(height, width, CV_8U);
    for (int i = 0; i < width * height; ++i) {
      const int row = scene.projector_row[i];
      int on = 0;
      if (row >= 0) {
        const int code = code_of_row(g.layout, row);
        const int column = scene.projector_column[i] * 2 / g.projector.width;
        on = pattern.at<std::uint8_t>(code, column) > 0;
      }
      image.data[i] = cv::saturate_cast<std::uint8_t>(20.0 + 180.0 * on + noise(random));
    }
    captured.push_back(image);
  }
  OpenCvTiming t;
  t.pattern_images = static_cast<int>(captured.size());
  std::vector<cv::Point> projector_pixel(static_cast<std::size_t>(width) * height);
  std::vector<std::uint8_t> decoded(projector_pixel.size());
  std::vector<double> decode_ms;
  for (int run = 0; run < runs; ++run) {
    decode_ms.push_back(time_ms([&] {
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          cv::Point p;
          const bool error = gray->getProjPixel(captured, x, y, p);
          projector_pixel[static_cast<std::size_t>(y) * width + x] = p;
          decoded[static_cast<std::size_t>(y) * width + x] = !error;
        }
      }
    }));
  }
  t.decode_ms = median(decode_ms);

  // Correspondences for cv::triangulatePoints: undistorted camera pixel and projector point
  // (x_p on the epipolar line of the camera pixel, y_p the code's centre row). Computing x_p is
  // our set-up for OpenCV (it has no row-only triangulation) and is not timed.
  const Eigen::Matrix3d K_c = g.camera.intrinsic_matrix(), K_p = g.projector.intrinsic_matrix();
  const Eigen::Vector3d tvec = g.t_projector_camera_m;
  Eigen::Matrix3d t_cross;
  t_cross << 0, -tvec.z(), tvec.y(), tvec.z(), 0, -tvec.x(), -tvec.y(), tvec.x(), 0;
  const Eigen::Matrix3d F =
      K_p.inverse().transpose() * t_cross * g.R_projector_camera * K_c.inverse();
  std::vector<int> index;
  cv::Mat camera_points(2, 0, CV_64F), projector_points(2, 0, CV_64F);
  std::vector<double> cx, cy, px, py;
  for (int i = 0; i < width * height; ++i) {
    if (!decoded[i]) continue;
    const Eigen::Vector3d ray = g.camera.ray(i % width, i / width);
    const Eigen::Vector3d u_c = K_c * ray;
    const double y_p = g.code_centre_row(projector_pixel[i].y);
    const Eigen::Vector3d line = F * u_c;
    if (std::abs(line.x()) < 1e-12) continue;
    index.push_back(i);
    cx.push_back(u_c.x());
    cy.push_back(u_c.y());
    px.push_back(-(line.y() * y_p + line.z()) / line.x());
    py.push_back(y_p);
  }
  const int count = static_cast<int>(index.size());
  t.decoded_pixels = count;
  cv::Mat points1(2, count, CV_64F), points2(2, count, CV_64F);
  std::copy(cx.begin(), cx.end(), points1.ptr<double>(0));
  std::copy(cy.begin(), cy.end(), points1.ptr<double>(1));
  std::copy(px.begin(), px.end(), points2.ptr<double>(0));
  std::copy(py.begin(), py.end(), points2.ptr<double>(1));
  cv::Mat C, P;
  cv::eigen2cv(Eigen::Matrix<double, 3, 4>(g.camera_matrix()), C);
  cv::eigen2cv(Eigen::Matrix<double, 3, 4>(g.projector_matrix()), P);
  cv::Mat points4d;
  std::vector<double> triangulate_ms;
  for (int run = 0; run < std::max(1, runs / 2); ++run) {
    triangulate_ms.push_back(
        time_ms([&] { cv::triangulatePoints(C, P, points1, points2, points4d); }));
  }
  t.triangulate_ms = median(triangulate_ms);
  double sum = 0;
  for (int j = 0; j < count; ++j) {
    const double z = points4d.at<double>(2, j) / points4d.at<double>(3, j);
    sum += std::pow(z - scene.true_depth_m[index[j]], 2);
  }
  t.rms_error_m = std::sqrt(sum / std::max(count, 1));
  return t;
}

bench::Report run(const std::vector<std::string>& args) {
  bench::Options options("decode", args);
  const int updates = static_cast<int>(options.integer("--updates", 300, 1, 1000000));
  const int opencv_runs = static_cast<int>(options.integer("--opencv-runs", 5, 1, 100000));
  options.finish();
  DecoderConfig config;
  PlaneSceneConfig scene_config;
  scene_config.seed = 5;
  const SyntheticScene scene = render_plane(config.geometry, scene_config);

  const RollingTiming avs = time_rolling(config, scene, updates);
  DecoderConfig reference_config = config;
  reference_config.triangulation = TriangulationMethod::kReferenceSolve;
  const RollingTiming reference = time_rolling(reference_config, scene, std::max(10, updates / 10));
  // The same update with a distorted camera: per-pixel ray tables instead of separable ones.
  DecoderConfig distorted_config = config;
  distorted_config.geometry.camera.k1 = -0.1;
  distorted_config.geometry.camera.k2 = 0.05;
  const SyntheticScene distorted_scene = render_plane(distorted_config.geometry, scene_config);
  const RollingTiming distorted = time_rolling(distorted_config, distorted_scene, updates);
  // Optional sub-code refinement (DecoderConfig::subcode_half_window = 4).
  DecoderConfig subcode_config = config;
  subcode_config.subcode_half_window = 4;
  const RollingTiming subcode = time_rolling(subcode_config, scene, updates);
  const InterleavedTiming interleaved = time_interleaved(config, subcode_config, scene, updates);
  const double subcode_cost = interleaved.subcode_ms / interleaved.plain_ms;
  const SubcodePasses passes = time_subcode_passes(subcode_config, scene, updates);
  const OpenCvTiming opencv =
      time_opencv(config.geometry, scene, config.threshold_psi, opencv_runs);

  bench::Report report;
  report.title = "decode: 512x512, 9-bit Gray code rows, plane at 1.0 m, one core";
  report.rows.push_back({"rolling 1-bit update + triangulation (2 frames in)", "ms",
                         avs.push_frames_ms, "per-pixel 3x3 solve of Eq. 4",
                         reference.push_frames_ms});
  report.rows.push_back({"rolling update (push_frame x2) vs OpenCV decode of a full cycle", "ms",
                         avs.push_frames_ms,
                         "OpenCV 4.6 GrayCodePattern getProjPixel, " +
                             std::to_string(opencv.pattern_images) + " images",
                         opencv.decode_ms});
  report.rows.push_back({"rolling update + triangulation vs OpenCV decode + triangulatePoints",
                         "ms", avs.push_frames_ms, "OpenCV getProjPixel + cv::triangulatePoints",
                         opencv.decode_ms + opencv.triangulate_ms});
  report.rows.push_back(
      {"rolling update, pair passed without copy (push_pair)", "ms", avs.push_pair_ms, "", 0});
  report.rows.push_back({"rolling update, distorted camera (per-pixel ray tables)", "ms",
                         distorted.push_frames_ms, "", 0});
  report.rows.push_back({"rolling update + sub-code refinement (h = 4, optional)", "ms",
                         subcode.push_frames_ms, "", 0});
  report.rows.push_back({"update + sub-code refinement, plain update timed in alternation", "ms",
                         interleaved.subcode_ms, "plain update, same pairs, alternating",
                         interleaved.plain_ms});
  report.json = {{"avs_update_ms", avs.push_frames_ms},
                 {"interleaved_update_ms", interleaved.plain_ms},
                 {"interleaved_update_subcode_ms", interleaved.subcode_ms},
                 {"subcode_cost_ratio", subcode_cost},
                 {"subcode_gray_to_code_ms", passes.gray_to_code_ms},
                 {"subcode_window_ms", passes.window_ms},
                 {"subcode_lookup_ms", passes.lookup_ms},
                 {"avs_update_subcode_ms", subcode.push_frames_ms},
                 {"avs_subcode_rms_error_mm", 1e3 * subcode.rms_error_m},
                 {"avs_update_pair_ms", avs.push_pair_ms},
                 {"avs_update_distorted_camera_ms", distorted.push_frames_ms},
                 {"reference_update_ms", reference.push_frames_ms},
                 {"opencv_decode_ms", opencv.decode_ms},
                 {"opencv_triangulate_ms", opencv.triangulate_ms},
                 {"speedup_vs_opencv", opencv.decode_ms / avs.push_frames_ms},
                 {"speedup_vs_opencv_with_triangulation",
                  (opencv.decode_ms + opencv.triangulate_ms) / avs.push_frames_ms},
                 {"speedup_vs_reference", reference.push_frames_ms / avs.push_frames_ms},
                 {"avs_rms_error_mm", 1e3 * avs.rms_error_m},
                 {"reference_rms_error_mm", 1e3 * reference.rms_error_m},
                 {"opencv_rms_error_mm", 1e3 * opencv.rms_error_m},
                 {"updates", updates}};
  char line[256];
  std::snprintf(
      line, sizeof line,
      "depth RMS vs ground truth: avs %.2f mm, reference %.2f mm, OpenCV %.2f mm (%d pixels "
      "decoded)",
      1e3 * avs.rms_error_m, 1e3 * reference.rms_error_m, 1e3 * opencv.rms_error_m,
      opencv.decoded_pixels);
  report.notes.push_back(line);
  report.notes.push_back(
      "medians over " + std::to_string(updates) + " updates (avs), " + std::to_string(opencv_runs) +
      " runs (OpenCV); OpenCV decodes a full cycle "
      "(it has no rolling mode), so its figure is per 9-bit map, ours per 1-bit update");
  report.notes.push_back(
      "OpenCV x_p for triangulatePoints comes from the epipolar line (not timed)");
  std::snprintf(line, sizeof line,
                "depth maps of 3 cycles, FNV-1a: plain %016llx, sub-code (h = 4) %016llx (equal "
                "across commits = bit-identical decoding)",
                static_cast<unsigned long long>(hash_depth_maps(config, scene)),
                static_cast<unsigned long long>(hash_depth_maps(subcode_config, scene)));
  report.notes.push_back(line);
  std::snprintf(line, sizeof line,
                "sub-code passes apart (h = 4): Gray to code %.3f ms (a pass of its own; the "
                "decoder has the codes from its update), window fit %.3f ms, plane look-up %.3f ms",
                passes.gray_to_code_ms, passes.window_ms, passes.lookup_ms);
  report.notes.push_back(line);
  std::snprintf(line, sizeof line,
                "sub-code refinement costs %.2fx the plain update, timed in alternation "
                "(subcode_cost_ratio; issue 16's goal: at most 2x)",
                subcode_cost);
  report.notes.push_back(line);
  report.notes.push_back(
      std::string("pair kernel: ") + detail::kernel_isa_name(detail::best_kernel_isa()) +
      "; distorted camera (k1 -0.1, k2 0.05) RMS " + std::to_string(1e3 * distorted.rms_error_m) +
      " mm; sub-code (h = 4) RMS " + std::to_string(1e3 * subcode.rms_error_m) + " mm");
  return report;
}

}  // namespace

AVS_REGISTER_BENCH(
    decode, "decode",
    "rolling Gray-code update + triangulation vs Eq. 4 solve vs OpenCV structured_light", run);

}  // namespace avs::decode
