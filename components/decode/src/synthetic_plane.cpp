#include "avs/decode/synthetic_plane.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace avs::decode {

PatternFrame SyntheticScene::frame(int bit_index, Polarity polarity, std::int64_t cycle) const {
  const auto& pixels =
      frames[static_cast<std::size_t>(2 * bit_index + (polarity == Polarity::kNegative))];
  return PatternFrame{{pixels.data(), width, height, width}, bit_index, polarity, cycle};
}

SyntheticScene render_plane(const SensorGeometry& g, const PlaneSceneConfig& config) {
  SyntheticScene scene;
  scene.width = g.camera.width;
  scene.height = g.camera.height;
  const auto pixels = static_cast<std::size_t>(scene.width) * scene.height;
  scene.true_depth_m.assign(pixels, static_cast<float>(config.plane_depth_m));
  scene.true_code.assign(pixels, -1);
  scene.lit.assign(pixels, 0);
  scene.shadowed.assign(pixels, 0);
  scene.projector_column.assign(pixels, -1);
  scene.projector_row.assign(pixels, -1);
  std::vector<int>& row_of_pixel = scene.projector_row;
  for (int v = 0; v < scene.height; ++v) {
    for (int u = 0; u < scene.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * scene.width + u;
      const bool shadow = u >= config.shadow_x0 && u < config.shadow_x1 && v >= config.shadow_y0 &&
                          v < config.shadow_y1;
      scene.shadowed[i] = shadow;
      const Eigen::Vector3d p_camera = config.plane_depth_m * g.camera.ray(u, v);
      const Eigen::Vector3d p_projector = g.R_projector_camera * p_camera + g.t_projector_camera_m;
      const Eigen::Vector2d uv = g.projector.project(p_projector);
      const int column = static_cast<int>(std::floor(uv.x() + 0.5));
      const int row = static_cast<int>(std::floor(uv.y() + 0.5));
      if (shadow || p_projector.z() <= 0 || column < 0 || column >= g.projector.width || row < 0 ||
          row >= g.projector.height) {
        continue;
      }
      const int code = code_of_row(g.layout, row);
      if (code < 0) continue;
      row_of_pixel[i] = row;
      scene.projector_column[i] = column;
      scene.true_code[i] = code;
      scene.lit[i] = 1;
    }
  }
  std::mt19937 random(config.seed);
  std::normal_distribution<double> noise(0.0, config.noise_sigma);
  for (int k = 0; k < g.layout.bit_count; ++k) {
    for (Polarity polarity : {Polarity::kPositive, Polarity::kNegative}) {
      std::vector<std::uint8_t> image(pixels);
      for (std::size_t i = 0; i < pixels; ++i) {
        const int on =
            row_of_pixel[i] < 0 ? 0 : pattern_value(g.layout, row_of_pixel[i], k, polarity);
        const double intensity = config.ambient + config.amplitude * on + noise(random);
        image[i] = static_cast<std::uint8_t>(std::clamp(std::lround(intensity), 0L, 255L));
      }
      scene.frames.push_back(std::move(image));
    }
  }
  return scene;
}

}  // namespace avs::decode
