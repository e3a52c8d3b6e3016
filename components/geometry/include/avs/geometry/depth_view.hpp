// The one borrowed depth image type of the cores (tracking, matching): z in metres along the
// optical axis per pixel, row-major, NaN (or 0, or non-finite) where nothing was measured. The
// message layer (avs/msg/depth_image.hpp) makes one from a sensor_msgs/Image without a copy.
#pragma once

#include <cstddef>

namespace avs::geometry {

struct DepthView {
  const float* depth_m = nullptr;
  int width_px = 0;
  int height_px = 0;
  int stride_px = 0;  ///< floats per row; 0 means width_px

  [[nodiscard]] int stride() const { return stride_px > 0 ? stride_px : width_px; }
  [[nodiscard]] float at(int u, int v) const {
    return depth_m[static_cast<std::size_t>(v) * static_cast<std::size_t>(stride()) +
                   static_cast<std::size_t>(u)];
  }
};

}  // namespace avs::geometry
