// The layout every depth consumer (tracking, matching, run_recorder) accepts on /depth/image:
// sensor_msgs/Image, encoding 32FC1, little-endian, metres, NaN invalid, rows `step` bytes apart.
// One check, one error text, one view type (geometry::DepthView), no copy.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "avs/geometry/depth_view.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/sample.hpp"

namespace avs::msg {

/// A view of the image's depth, or nullopt with `why` set to what is wrong and what was expected.
inline std::optional<geometry::DepthView> depth_view(const msgs::sensor_msgs::Image& image,
                                                     std::string* why = nullptr) {
  const std::string_view encoding = runtime::get_string(image.encoding);
  if (encoding != "32FC1" || image.is_bigendian != 0 || image.step % 4 != 0 ||
      static_cast<std::uint64_t>(image.step) * image.height > image.data._length ||
      image.step < 4ull * image.width || image.width == 0 || image.height == 0 ||
      image.width > (1u << 20) || image.height > (1u << 20)) {
    if (why != nullptr) {
      *why = "depth image '" + std::string(encoding) + "' " + std::to_string(image.width) + "x" +
             std::to_string(image.height) + " step " + std::to_string(image.step) + " (" +
             std::to_string(image.data._length) +
             " bytes): expected little-endian 32FC1 metres, 1..2^20 pixels a side, step >= 4 x "
             "width";
    }
    return std::nullopt;
  }
  return geometry::DepthView{reinterpret_cast<const float*>(image.data._buffer),
                             static_cast<int>(image.width), static_cast<int>(image.height),
                             static_cast<int>(image.step / 4)};
}

}  // namespace avs::msg
