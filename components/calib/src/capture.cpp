#include "avs/calib/capture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace avs::calib {
namespace {

decode::CodeLayout codes_over(int pixels, int pixels_per_code) {
  decode::CodeLayout layout;
  layout.code_count = pixels / pixels_per_code;
  layout.bit_count = 1;
  while ((1 << layout.bit_count) < layout.code_count) ++layout.bit_count;
  layout.rows_per_code = pixels_per_code;
  layout.first_row = (pixels - layout.used_rows()) / 2;  // centred, as the paper's rows
  return layout;
}

decode::GrayImage8 to_gray(sim::MonoImage&& image) {
  return decode::GrayImage8{image.width, image.height, std::move(image.pixels)};
}

/// splitmix64 as a uniform generator: the same numbers on every platform and library.
class Uniform {
 public:
  explicit Uniform(std::uint64_t seed) : state_(seed) {}
  double operator()(double lo, double hi) {
    state_ += 0x9E3779B97F4A7C15ull;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return lo + (hi - lo) * static_cast<double>(z >> 11) / 9007199254740992.0;
  }

 private:
  std::uint64_t state_;
};

constexpr double kDegToRad = std::numbers::pi / 180.0;

}  // namespace

std::string FrameId::file_name() const {
  char name[32];
  switch (kind) {
    case FrameKind::kWhite:
      return "white.png";
    case FrameKind::kBlack:
      return "black.png";
    case FrameKind::kColumnBit:
    case FrameKind::kRowBit:
      std::snprintf(name, sizeof name, "%s_%02d_%s.png",
                    kind == FrameKind::kColumnBit ? "column" : "row", bit,
                    positive ? "pos" : "neg");
      return name;
  }
  return {};
}

std::string FrameId::label() const {
  const std::string name = file_name();
  return name.substr(0, name.size() - 4);
}

CaptureCodes calibration_codes(int projector_width, int projector_height, int pixels_per_code) {
  if (pixels_per_code < 1 || pixels_per_code > projector_width / 4 ||
      pixels_per_code > projector_height / 4) {
    throw std::invalid_argument("calib: pixels_per_code " + std::to_string(pixels_per_code) +
                                " does not fit the projector");
  }
  return {projector_width, projector_height, codes_over(projector_width, pixels_per_code),
          codes_over(projector_height, pixels_per_code)};
}

std::vector<FrameId> capture_frames(const CaptureCodes& codes) {
  std::vector<FrameId> frames{{FrameKind::kWhite}, {FrameKind::kBlack}};
  for (int k = 0; k < codes.columns.bit_count; ++k) {
    frames.push_back({FrameKind::kColumnBit, k, true});
    frames.push_back({FrameKind::kColumnBit, k, false});
  }
  for (int k = 0; k < codes.rows.bit_count; ++k) {
    frames.push_back({FrameKind::kRowBit, k, true});
    frames.push_back({FrameKind::kRowBit, k, false});
  }
  return frames;
}

namespace {

sim::RendererConfig calibration_renderer(sim::RendererConfig config, const CaptureCodes& codes) {
  // The renderer's row code is the capture's full-resolution row code; its column code the
  // column code. The rig's own 500 Hz layout is kept in CaptureInfo.
  config.geometry.layout = codes.rows;
  config.column_layout = codes.columns;
  return config;
}

}  // namespace

SimCapture::SimCapture(const sim::RendererConfig& renderer, const sim::Checkerboard& board,
                       int pixels_per_code)
    : renderer_(calibration_renderer(
          renderer, calibration_codes(renderer.geometry.projector.width,
                                      renderer.geometry.projector.height, pixels_per_code))),
      mesh_(sim::make_checkerboard_mesh(board)) {
  if (const std::string why = board.problem(); !why.empty()) {
    throw std::invalid_argument("calib::SimCapture: board: " + why);
  }
  info_.source = "sim";
  info_.board = board;
  info_.camera_width = renderer.geometry.camera.width;
  info_.camera_height = renderer.geometry.camera.height;
  info_.codes = calibration_codes(renderer.geometry.projector.width,
                                  renderer.geometry.projector.height, pixels_per_code);
  info_.depth_code_layout = renderer.geometry.layout;
  info_.truth = renderer.geometry;
}

BoardView SimCapture::render(const Eigen::Isometry3d& T_camera_board, int view_index,
                             const std::string& name) {
  sim::RenderObject board{&mesh_, T_camera_board, 0.0, &info_.board};
  renderer_.set_view({board});
  BoardView view;
  view.name = name;
  view.T_camera_board_truth = T_camera_board;
  const std::vector<FrameId> frames = capture_frames(info_.codes);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    static constexpr sim::ProjectorFrame kKinds[] = {
        sim::ProjectorFrame::kWhite, sim::ProjectorFrame::kBlack, sim::ProjectorFrame::kColumnBit,
        sim::ProjectorFrame::kRowBit};
    const FrameId& id = frames[f];
    sim::MonoImage image;
    renderer_.shade({kKinds[static_cast<int>(id.kind)], id.bit, id.positive},
                    sim::frame_noise_key(static_cast<std::uint64_t>(view_index) * 1000 + f), image);
    view.frames.push_back(to_gray(std::move(image)));
  }
  return view;
}

PoseVisibility pose_visibility(const decode::SensorGeometry& g, const sim::Checkerboard& board,
                               const Eigen::Isometry3d& T_camera_board, double margin_px) {
  const auto inside = [margin_px](const geometry::CameraModel& lens, const Eigen::Vector3d& p) {
    if (!(p.z() > 0.05)) return false;
    const Eigen::Vector2d uv = lens.project(p);
    return uv.x() >= margin_px && uv.y() >= margin_px && uv.x() <= lens.width - 1 - margin_px &&
           uv.y() <= lens.height - 1 - margin_px;
  };
  // The plate's own corners too: the detector needs the light border around the squares.
  const double hx = 0.5 * board.width_m(), hy = 0.5 * board.height_m();
  for (const Eigen::Vector3d& plate : {Eigen::Vector3d(-hx, -hy, 0), Eigen::Vector3d(hx, -hy, 0),
                                       Eigen::Vector3d(-hx, hy, 0), Eigen::Vector3d(hx, hy, 0)}) {
    const Eigen::Vector3d p_camera = T_camera_board * plate;
    if (!inside(g.camera, p_camera) ||
        !inside(g.projector, g.R_projector_camera * p_camera + g.t_projector_camera_m)) {
      return {};
    }
  }
  int camera = 0, projector = 0;
  for (int j = 0; j < board.inner_corners_y(); ++j) {
    for (int i = 0; i < board.inner_corners_x(); ++i) {
      const Eigen::Vector3d p_camera = T_camera_board * board.corner_board_m(i, j);
      camera += inside(g.camera, p_camera) ? 1 : 0;
      projector +=
          inside(g.projector, g.R_projector_camera * p_camera + g.t_projector_camera_m) ? 1 : 0;
    }
  }
  const double n = board.corner_count();
  return {camera / n, projector / n};
}

Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, const Eigen::Vector3d& rpy_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = xyz_m;
  T.linear() = (Eigen::AngleAxisd(rpy_deg.z() * kDegToRad, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(rpy_deg.y() * kDegToRad, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(rpy_deg.x() * kDegToRad, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

std::vector<Eigen::Isometry3d> generate_board_poses(const decode::SensorGeometry& geometry,
                                                    const sim::Checkerboard& board, int count,
                                                    double near_m, double far_m,
                                                    double max_tilt_deg, std::uint64_t seed) {
  if (count < 1 || !(near_m > 0) || !(far_m >= near_m)) {
    throw std::invalid_argument("calib: need count >= 1 and 0 < near_m <= far_m");
  }
  Uniform uniform(seed);
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < count; ++k) {
    // Stratified distance: pose k in the k-th of `count` equal slices of [near, far].
    const double z0 = near_m + (far_m - near_m) * k / count;
    const double z1 = near_m + (far_m - near_m) * (k + 1) / count;
    bool placed = false;
    for (int attempt = 0; attempt < 2000 && !placed; ++attempt) {
      const double z = uniform(z0, z1);
      // The board's centre towards one of 3 x 3 regions of the camera image in turn (so that
      // the corners of all views spread over the image), jittered; after 200 misses anywhere
      // the camera sees at that distance. The visibility test decides.
      const int region = (k * 4) % 9;  // 0, 4, 8, 3, 7, 2, 6, 1, 5: distance and region mixed
      const double spread = attempt < 200 ? 1.0 / 3.0 : 1.0;
      const double u =
          (attempt < 200 ? (region % 3 + 0.5) / 3.0 : 0.5) + uniform(-0.5, 0.5) * spread;
      const double v =
          (attempt < 200 ? (region / 3 + 0.5) / 3.0 : 0.5) + uniform(-0.5, 0.5) * spread;
      const Eigen::Vector3d xyz = z * geometry.camera.ray(u * (geometry.camera.width - 1),
                                                          v * (geometry.camera.height - 1));
      const Eigen::Vector3d rpy(180.0 + uniform(-max_tilt_deg, max_tilt_deg),
                                uniform(-max_tilt_deg, max_tilt_deg), uniform(-20.0, 20.0));
      const Eigen::Isometry3d T = pose_from_xyz_rpy(xyz, rpy);
      const PoseVisibility seen = pose_visibility(geometry, board, T, 15.0);
      if (seen.camera == 1.0 && seen.projector == 1.0) {
        poses.push_back(T);
        placed = true;
      }
    }
    if (!placed) {
      throw std::runtime_error("calib: cannot place a board pose at " + std::to_string(z0) + "-" +
                               std::to_string(z1) +
                               " m in view of both camera and projector (board too large?)");
    }
  }
  return poses;
}

}  // namespace avs::calib
