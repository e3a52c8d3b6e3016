// Issue 14, section 1: the renderer shows what a calibration capture needs and a real rig has.
// Column and row Gray codes, white and black frames, any projector pose (R, t) and projector
// lens distortion, checked against decode's own projection (not the renderer's code paths),
// and a plane decoded by decode::RollingDecoder through a rotated, distorted projector.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/gray_code.hpp"
#include "avs/decode/rolling_decoder.hpp"
#include "avs/geometry/primitives.hpp"
#include "avs/sim/renderer.hpp"

namespace avs::sim {
namespace {

/// A projector beside and below the camera, turned by a few degrees about every axis, with
/// barrel and tangential distortion: nothing like the paper's pure y baseline.
decode::SensorGeometry rotated_distorted_geometry() {
  decode::SensorGeometry g = decode::default_sensor_geometry();
  const Eigen::Vector3d centre_camera(0.05, 0.19, 0.01);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.19, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(-0.04, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix()
                                .transpose();
  g.R_projector_camera = R;
  g.t_projector_camera_m = -R * centre_camera;
  g.projector.k1 = -0.05;
  g.projector.k2 = 0.02;
  g.projector.p1 = 0.0006;
  g.projector.p2 = -0.0004;
  g.projector.cx_px += 7.0;
  g.projector.cy_px -= 5.0;
  return g;
}

/// Full-resolution codes over the DMD's columns: one column per code.
decode::CodeLayout column_layout(int width) {
  decode::CodeLayout c;
  c.bit_count = 10;
  c.code_count = width;
  c.rows_per_code = 1;
  c.first_row = 0;
  return c;
}

RenderObject plane_facing_camera(const geometry::Mesh& mesh, double distance_m, double tilt_rad) {
  RenderObject o;
  o.mesh = &mesh;
  o.T_camera_object = Eigen::Translation3d(0, 0, distance_m) *
                      Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
  o.albedo = 0.6;
  return o;
}

/// Where pixel (x, y)'s ray meets the plane of `o` (its local z = 0), in the camera frame.
Eigen::Vector3d ray_plane(const decode::SensorGeometry& g, const RenderObject& o, int x, int y) {
  const Eigen::Vector3d ray = g.camera.ray(x, y);
  const Eigen::Vector3d n = o.T_camera_object.linear().col(2), c = o.T_camera_object.translation();
  return ray * (n.dot(c) / n.dot(ray));
}

TEST(CalibrationPatterns, ColumnAndRowBitsMatchTheDmdPixelOfARotatedDistortedProjector) {
  RendererConfig config;
  config.geometry = rotated_distorted_geometry();
  config.column_layout = column_layout(config.geometry.projector.width);
  const decode::SensorGeometry& g = config.geometry;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  const RenderObject object = plane_facing_camera(plane, 1.0, 0.25);
  renderer.set_view({object});
  const decode::CodeLayout& columns = *config.column_layout;
  const auto frame = [&](ProjectorFrame kind, int k, bool positive, std::uint64_t key) {
    MonoImage image;
    renderer.shade(FramePattern{kind, k, positive}, frame_noise_key(key), image);
    return image;
  };
  long checks = 0, agree = 0, lit = 0, column_truth_near = 0;
  const MonoImage white = frame(ProjectorFrame::kWhite, 0, true, 1);
  const MonoImage black = frame(ProjectorFrame::kBlack, 0, true, 2);
  std::vector<MonoImage> row_p, row_n, col_p, col_n;
  for (int k = 0; k < g.layout.bit_count; ++k) {
    row_p.push_back(frame(ProjectorFrame::kRowBit, k, true, 10 + 2 * k));
    row_n.push_back(frame(ProjectorFrame::kRowBit, k, false, 11 + 2 * k));
  }
  for (int k = 0; k < columns.bit_count; ++k) {
    col_p.push_back(frame(ProjectorFrame::kColumnBit, k, true, 40 + 2 * k));
    col_n.push_back(frame(ProjectorFrame::kColumnBit, k, false, 41 + 2 * k));
  }
  for (int y = 0; y < renderer.height(); ++y) {
    for (int x = 0; x < renderer.width(); ++x) {
      const Eigen::Vector3d p_camera = ray_plane(g, object, x, y);
      const Eigen::Vector2d uv =
          g.projector.project(g.R_projector_camera * p_camera + g.t_projector_camera_m);
      if (!g.projector.contains(uv)) continue;
      const int column = static_cast<int>(std::lround(uv.x()));
      const int row = static_cast<int>(std::lround(uv.y()));
      ++lit;
      const std::size_t i = static_cast<std::size_t>(y) * renderer.width() + x;
      column_truth_near += std::abs(renderer.projector_column()[i] - uv.x()) < 0.05 ? 1 : 0;
      // White is brighter than black wherever the projector lights the plane.
      ++checks;
      agree += white.at(x, y) > black.at(x, y) + 20 ? 1 : 0;
      for (int k = 0; k < columns.bit_count; ++k) {
        ++checks;
        const int bit = col_p[k].at(x, y) > col_n[k].at(x, y) ? 1 : 0;
        agree += bit == decode::pattern_bit(columns, column, k) ? 1 : 0;
      }
      if (decode::code_of_row(g.layout, row) < 0) continue;
      for (int k = 0; k < g.layout.bit_count; ++k) {
        ++checks;
        const int bit = row_p[k].at(x, y) > row_n[k].at(x, y) ? 1 : 0;
        agree += bit == decode::pattern_bit(g.layout, row, k) ? 1 : 0;
      }
    }
  }
  const double fraction = double(agree) / double(checks);
  std::printf("lit %ld px, bit agreement %.5f, column truth within 0.05 px: %ld\n", lit, fraction,
              column_truth_near);
  EXPECT_GT(lit, renderer.width() * renderer.height() / 2);
  EXPECT_GE(fraction, 0.99);
  EXPECT_GE(column_truth_near, lit * 99 / 100);
}

TEST(CalibrationPatterns, WhiteAndColumnFramesNeedTheColumnLayout) {
  Renderer renderer(RendererConfig{});
  MonoImage image;
  EXPECT_THROW(renderer.shade(FramePattern{ProjectorFrame::kWhite, 0, true}, 0, image),
               std::logic_error);
  EXPECT_THROW(renderer.shade(FramePattern{ProjectorFrame::kColumnBit, 0, true}, 0, image),
               std::logic_error);
  EXPECT_THROW(renderer.shade(FramePattern{ProjectorFrame::kRowBit, 9, true}, 0, image),
               std::invalid_argument);
  // With calibration patterns, motion blur (which ignores the per-pixel sub-samples) refuses.
  RendererConfig calibration;
  calibration.column_layout = column_layout(calibration.geometry.projector.width);
  Renderer calibration_renderer(calibration);
  std::vector<float> sum;
  EXPECT_THROW(calibration_renderer.accumulate(0, true, 1.0f, sum), std::logic_error);
}

/// Decodes one cycle of a plane at 1 m; returns the fraction of coded pixels whose depth error
/// is within half a code's depth step (+1 mm), after checking the codes and the median.
double decoded_plane_within_half_code(const decode::SensorGeometry& geometry) {
  RendererConfig config;
  config.geometry = geometry;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({plane_facing_camera(plane, 1.0, 0.1)});
  decode::DecoderConfig decoder_config;
  decoder_config.geometry = geometry;
  decode::RollingDecoder decoder(decoder_config);
  decode::DecodeResult result;
  std::vector<MonoImage> frames;  // the decoder may keep views into the images
  const int bits = geometry.layout.bit_count;
  frames.reserve(2 * bits);
  for (int f = 0; f < 2 * bits; ++f) {
    frames.emplace_back();
    renderer.shade(f / 2, f % 2 == 0, frame_noise_key(f), frames.back());
    decode::PatternFrame input;
    input.image = {frames.back().pixels.data(), frames.back().width, frames.back().height, 0};
    input.bit_index = f / 2;
    input.polarity = f % 2 == 0 ? decode::Polarity::kPositive : decode::Polarity::kNegative;
    result = decoder.push_frame(input);
  }
  EXPECT_TRUE(result.depth_updated);
  std::vector<double> errors_mm;
  const std::vector<int> codes = decoder.code_map();
  const decode::DepthTable table(geometry);
  long coded = 0, same_code = 0, within_half_code = 0;
  for (std::size_t i = 0; i < result.depth_m.size(); ++i) {
    if (renderer.code()[i] < 0) continue;
    ++coded;
    same_code += codes[i] == renderer.code()[i] ? 1 : 0;
    if (!std::isfinite(result.depth_m[i])) continue;
    const double error_m = std::abs(result.depth_m[i] - renderer.depth_m()[i]);
    errors_mm.push_back(1000.0 * error_m);
    // Code-centre triangulation errs by at most half a code's depth step.
    const int pixel = static_cast<int>(i), c = renderer.code()[i];
    const int last = geometry.layout.code_count - 1;
    const double step_m =
        std::max(std::abs(table.depth(pixel, std::min(c + 1, last)) - table.depth(pixel, c)),
                 std::abs(table.depth(pixel, c) - table.depth(pixel, std::max(c - 1, 0))));
    within_half_code += error_m <= 0.5 * step_m + 1e-3 ? 1 : 0;
  }
  EXPECT_GT(errors_mm.size(), 100000u);
  if (errors_mm.empty()) return 0;
  std::sort(errors_mm.begin(), errors_mm.end());
  const double median = errors_mm[errors_mm.size() / 2];
  std::printf(
      "decoded %zu px, same code %ld of %ld: median %.2f mm, p99 %.2f mm, within half "
      "a code %ld; decoder's plane fit error %.5f\n",
      errors_mm.size(), same_code, coded, median, errors_mm[errors_mm.size() * 99 / 100],
      within_half_code, table.max_plane_fit_error());
  EXPECT_GE(same_code, coded * 98 / 100);
  // A code spans 4 projector rows, ~18 mm of depth at 1 m (decode_roundtrip_test).
  EXPECT_LT(median, 6.0);
  return double(within_half_code) / double(coded);
}

TEST(CalibrationPatterns, APlaneDecodesToItsDepthThroughARotatedProjector) {
  decode::SensorGeometry g = rotated_distorted_geometry();
  g.projector.set_distortion_coefficients({});
  EXPECT_GE(decoded_plane_within_half_code(g), 0.999);
}

TEST(CalibrationPatterns, APlaneDecodesToItsCodesThroughARotatedDistortedProjector) {
  // Every code right; the depth is then as good as decode's plane-per-code table allows: it
  // fits a plane to each (curved) distorted row, which costs a few mm here (the printed fit
  // error), a decoder limitation this test does not hide: only 90 % are within half a code.
  EXPECT_GE(decoded_plane_within_half_code(rotated_distorted_geometry()), 0.90);
}

TEST(CalibrationPatterns, ACheckerboardShowsItsSquaresAroundEachProjectedCorner) {
  RendererConfig config;
  config.geometry = rotated_distorted_geometry();
  config.geometry.camera.k1 = -0.08;  // the camera's lens too
  config.geometry.camera.p1 = 0.0005;
  config.column_layout = column_layout(config.geometry.projector.width);
  config.noise_sigma_dn = 0;
  Renderer renderer(config);
  const decode::SensorGeometry& g = config.geometry;
  const Checkerboard board;  // 10 x 7 squares of 30 mm
  const geometry::Mesh mesh = make_checkerboard_mesh(board);
  RenderObject object;
  object.mesh = &mesh;
  object.checkerboard = &board;
  object.T_camera_object = Eigen::Translation3d(0.03, -0.02, 0.8) *
                           Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
                           Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
  renderer.set_view({object});
  MonoImage white;
  renderer.shade(FramePattern{ProjectorFrame::kWhite, 0, true}, 0, white);
  // Around each inner corner, the four squares' centres (a third of a square away along the
  // board's diagonals) alternate dark / light, as the board frame says.
  int corners = 0, right = 0, blurred_edges = 0;
  for (int j = 0; j < board.inner_corners_y(); ++j) {
    for (int i = 0; i < board.inner_corners_x(); ++i) {
      ++corners;
      bool ok = true;
      for (const auto& [sx, sy] : {std::pair{-1, -1}, {1, -1}, {-1, 1}, {1, 1}}) {
        const Eigen::Vector3d p_board =
            board.corner_board_m(i, j) + Eigen::Vector3d(sx, sy, 0) * board.square_m / 3;
        const Eigen::Vector2d uv = g.camera.project(object.T_camera_object * p_board);
        const int value =
            white.at(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
        const bool dark = board.albedo(p_board.x(), p_board.y()) == board.dark_albedo;
        ok = ok && (dark ? value < 60 : value > 120);
      }
      right += ok ? 1 : 0;
      // The corner's own pixel is a mix of the four squares.
      const Eigen::Vector2d c =
          g.camera.project(object.T_camera_object * board.corner_board_m(i, j));
      const int at_corner =
          white.at(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())));
      blurred_edges += at_corner > 30 && at_corner < 170 ? 1 : 0;
    }
  }
  EXPECT_EQ(right, corners);
  EXPECT_GE(blurred_edges, corners * 9 / 10);
  RenderObject bad = object;
  const Checkerboard square_board{.squares_x = 6, .squares_y = 6};
  bad.checkerboard = &square_board;
  EXPECT_THROW(renderer.set_view({bad}), std::invalid_argument);
}

}  // namespace
}  // namespace avs::sim
