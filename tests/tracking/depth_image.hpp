// A small synthetic depth image and camera for the tracking core's tests.
#pragma once

#include <vector>

#include "avs/geometry/camera_model.hpp"
#include "avs/geometry/depth_view.hpp"

namespace avs::tracking::test {

struct Image {
  int width = 64;
  int height = 48;
  std::vector<float> depth = std::vector<float>(64 * 48, 3.0F);  // background beyond phi_h
  [[nodiscard]] geometry::DepthView view() const { return {depth.data(), width, height, 0}; }
  void fill_rect(int u0, int v0, int w, int h, float d) {
    for (int v = v0; v < v0 + h; ++v)
      for (int u = u0; u < u0 + w; ++u) depth[static_cast<std::size_t>(v * width + u)] = d;
  }
};

inline const geometry::CameraModel kCamera{
    .width = 64, .height = 48, .fx_px = 100.0, .fy_px = 100.0, .cx_px = 31.5, .cy_px = 23.5};

}  // namespace avs::tracking::test
