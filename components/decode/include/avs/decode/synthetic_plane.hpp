// Test and benchmark aid (no I/O): the Gray-code frames a camera sees of a plane facing the sensor,
// computed analytically from the same SensorGeometry the decoder uses, with seeded Gaussian noise.
#pragma once

#include <cstdint>
#include <vector>

#include "avs/decode/rolling_decoder.hpp"

namespace avs::decode {

struct PlaneSceneConfig {
  double plane_depth_m = 1.0;  ///< plane z = D in the camera frame
  double ambient = 20;         ///< intensity without projector light
  double amplitude = 180;      ///< added where the projector pixel is on
  double noise_sigma = 2.0;    ///< Gaussian, per frame and pixel
  std::uint32_t seed = 1;
  /// Camera pixels in [x0, x1) x [y0, y1) are shadowed (no projector light).
  int shadow_x0 = 0, shadow_y0 = 0, shadow_x1 = 0, shadow_y1 = 0;
};

struct SyntheticScene {
  int width = 0;
  int height = 0;
  std::vector<std::vector<std::uint8_t>> frames;  ///< 2n, projection order
  std::vector<float> true_depth_m;                ///< per pixel
  std::vector<int> true_code;                     ///< -1 where not lit
  std::vector<std::uint8_t> lit;                  ///< directly lit by a coded projector row
  std::vector<std::uint8_t> shadowed;
  /// Projector pixel lighting each camera pixel (-1 where not lit), for rendering other patterns.
  std::vector<int> projector_column;
  std::vector<int> projector_row;

  PatternFrame frame(int bit_index, Polarity polarity, std::int64_t cycle) const;
};

SyntheticScene render_plane(const SensorGeometry& geometry, const PlaneSceneConfig& config);

}  // namespace avs::decode
