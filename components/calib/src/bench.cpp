#include "avs/calib/bench.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "avs/decode/rolling_decoder.hpp"
#include "avs/geometry/primitives.hpp"

namespace avs::calib {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

/// Worst difference (px) between two lenses' distortion over a grid of the image: where each
/// sends the same ideal ray.
double distortion_difference_px(const geometry::CameraModel& truth,
                                const geometry::CameraModel& estimate) {
  double worst = 0;
  for (int j = 0; j <= 8; ++j) {
    for (int i = 0; i <= 8; ++i) {
      const double u = i * (truth.width - 1) / 8.0, v = j * (truth.height - 1) / 8.0;
      const Eigen::Vector2d ideal = truth.undistort(
          Eigen::Vector2d((u - truth.cx_px) / truth.fx_px, (v - truth.cy_px) / truth.fy_px));
      const Eigen::Vector2d a = truth.distort(ideal), b = estimate.distort(ideal);
      worst =
          std::max(worst, std::hypot((a.x() - b.x()) * truth.fx_px, (a.y() - b.y()) * truth.fy_px));
    }
  }
  return worst;
}

struct PlaneDepth {
  std::vector<float> depth_m;  ///< decoded, NaN where none
  std::vector<float> truth_m;  ///< rendered, NaN where no code lights the pixel
};

/// One cycle of a plane at `distance_m` rendered with `truth`, decoded with `decoder_geometry`.
PlaneDepth plane_depth(const decode::SensorGeometry& truth,
                       const decode::SensorGeometry& decoder_geometry, double distance_m);

}  // namespace

decode::SensorGeometry bench_truth_geometry() {
  decode::SensorGeometry g = decode::default_sensor_geometry();
  g.camera.fx_px = 612.0;
  g.camera.fy_px = 615.0;
  g.camera.cx_px = 259.4;
  g.camera.cy_px = 251.7;
  g.camera.k1 = -0.09;
  g.camera.k2 = 0.05;
  g.camera.p1 = 0.0006;
  g.camera.p2 = -0.0004;
  g.projector.cx_px += 6.0;
  g.projector.cy_px -= 9.0;
  g.projector.k1 = -0.04;
  g.projector.p1 = 0.0005;
  g.projector.p2 = 0.0003;
  // Projector centre 0.2 m below the camera, 2 cm to the side, turned 1.5 deg about its axis
  // and aimed at the camera axis at 1 m.
  const Eigen::Vector3d centre(0.02, 0.2, 0.005);
  const Eigen::Vector3d z_axis = (Eigen::Vector3d(0, 0, 1.0) - centre).normalized();
  const Eigen::Vector3d x0 = Eigen::AngleAxisd(0.026, z_axis) * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y_axis = z_axis.cross(x0).normalized();
  const Eigen::Vector3d x_axis = y_axis.cross(z_axis);
  g.R_projector_camera.row(0) = x_axis.transpose();
  g.R_projector_camera.row(1) = y_axis.transpose();
  g.R_projector_camera.row(2) = z_axis.transpose();
  g.t_projector_camera_m = -g.R_projector_camera * centre;
  return g;
}

namespace {

PlaneDepth plane_depth(const decode::SensorGeometry& truth,
                       const decode::SensorGeometry& decoder_geometry, double distance_m) {
  sim::RendererConfig config;
  config.geometry = truth;
  sim::Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  sim::RenderObject object{
      &plane,
      Eigen::Isometry3d(Eigen::Translation3d(0, 0, distance_m) *
                        Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitY()) *
                        Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX())),
      0.6};
  renderer.set_view({object});
  decode::DecoderConfig decoder_config;
  decoder_config.geometry = decoder_geometry;
  decode::RollingDecoder decoder(decoder_config);
  decode::DecodeResult result;
  std::vector<sim::MonoImage> frames(static_cast<std::size_t>(2 * truth.layout.bit_count));
  for (std::size_t f = 0; f < frames.size(); ++f) {
    renderer.shade(static_cast<int>(f / 2), f % 2 == 0, sim::frame_noise_key(f), frames[f]);
    decode::PatternFrame input;
    input.image = {frames[f].pixels.data(), frames[f].width, frames[f].height, 0};
    input.bit_index = static_cast<int>(f / 2);
    input.polarity = f % 2 == 0 ? decode::Polarity::kPositive : decode::Polarity::kNegative;
    result = decoder.push_frame(input);
  }
  PlaneDepth out;
  out.depth_m.assign(result.depth_m.begin(), result.depth_m.end());
  out.truth_m = renderer.depth_m();
  for (std::size_t i = 0; i < out.truth_m.size(); ++i) {
    if (renderer.code()[i] < 0) out.truth_m[i] = std::numeric_limits<float>::quiet_NaN();
  }
  return out;
}

}  // namespace

double plane_depth_rms_mm(const decode::SensorGeometry& truth,
                          const decode::SensorGeometry& decoder, double distance_m) {
  const PlaneDepth true_calibration = plane_depth(truth, truth, distance_m);
  const PlaneDepth plane = plane_depth(truth, decoder, distance_m);
  // Over the pixels that both decode (and the renderer codes), so that a calibration which
  // loses pixels is not judged on fewer, easier ones.
  double sum2 = 0;
  long count = 0;
  for (std::size_t i = 0; i < plane.depth_m.size(); ++i) {
    if (!std::isfinite(plane.truth_m[i]) || !std::isfinite(plane.depth_m[i]) ||
        !std::isfinite(true_calibration.depth_m[i])) {
      continue;
    }
    const double e = plane.depth_m[i] - plane.truth_m[i];
    sum2 += e * e;
    ++count;
  }
  return count > 0 ? 1000.0 * std::sqrt(sum2 / static_cast<double>(count)) : 0.0;
}

BenchResult run_calibration_bench(const BenchConfig& config, std::FILE* progress) {
  sim::RendererConfig renderer;
  renderer.geometry = config.truth;
  renderer.noise_sigma_dn = config.noise_sigma_dn;
  renderer.noise_seed = config.seed;
  SimCapture capture(renderer, config.board);
  const std::vector<Eigen::Isometry3d> poses =
      generate_board_poses(config.truth, config.board, config.views, config.near_m, config.far_m,
                           config.max_tilt_deg, config.seed);
  std::vector<ViewObservation> observations;
  for (std::size_t v = 0; v < poses.size(); ++v) {
    char name[32];
    std::snprintf(name, sizeof name, "pose_%03zu", v);
    const BoardView view = capture.render(poses[v], static_cast<int>(v), name);
    observations.push_back(observe_view(view, capture.info(), config.observe));
    if (progress) {
      const ViewObservation& o = observations.back();
      std::fprintf(progress, "view %zu/%zu (z %.2f m): %s, %d of %zu corners with codes\n", v + 1,
                   poses.size(), poses[v].translation().z(),
                   o.board_found ? "board found" : o.problem.c_str(), o.corners_with_projector(),
                   o.corners.size());
    }
  }
  BenchResult out;
  out.calibration = solve_calibration(capture.info(), observations, config.solve);
  const decode::SensorGeometry& t = config.truth;
  const decode::SensorGeometry& e = out.calibration.geometry;
  if (out.calibration.views_used < 3) return out;  // nothing solved
  for (const auto& [truth, estimate] :
       {std::pair{&t.camera, &e.camera}, std::pair{&t.projector, &e.projector}}) {
    out.focal_error_pct =
        std::max({out.focal_error_pct, 100 * std::abs(estimate->fx_px / truth->fx_px - 1),
                  100 * std::abs(estimate->fy_px / truth->fy_px - 1)});
    out.principal_point_error_px =
        std::max({out.principal_point_error_px, std::abs(estimate->cx_px - truth->cx_px),
                  std::abs(estimate->cy_px - truth->cy_px)});
    out.distortion_error_px =
        std::max(out.distortion_error_px, distortion_difference_px(*truth, *estimate));
  }
  out.baseline_error_mm = 1000 * (e.t_projector_camera_m - t.t_projector_camera_m).norm();
  out.rotation_error_deg =
      kRadToDeg *
      Eigen::AngleAxisd(e.R_projector_camera * t.R_projector_camera.transpose()).angle();
  out.plane_rms_true_mm = plane_depth_rms_mm(t, t, config.plane_distance_m);
  out.plane_rms_recovered_mm = plane_depth_rms_mm(t, e, config.plane_distance_m);
  out.plane_rms_ratio = out.plane_rms_recovered_mm / out.plane_rms_true_mm;
  return out;
}

}  // namespace avs::calib
