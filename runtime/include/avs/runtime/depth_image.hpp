// The layout every depth consumer (tracking, matching, run_recorder) accepts on /depth/image:
// sensor_msgs/Image, encoding 32FC1, little-endian, metres, NaN invalid, rows `step` bytes apart.
// One check, one error text, instead of a copy in each component.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/sample.hpp"

namespace avs::runtime {

struct DepthImageLayout {
  const float* depth_m = nullptr;
  int width = 0;
  int height = 0;
  int row_stride_floats = 0;
};

/// The image's layout, or nullopt with `why` set to what is wrong and what was expected.
inline std::optional<DepthImageLayout> depth_image_layout(const msgs::sensor_msgs::Image& image,
                                                          std::string* why = nullptr) {
  const std::string_view encoding = get_string(image.encoding);
  if (encoding != "32FC1" || image.is_bigendian != 0 || image.step % 4 != 0 ||
      static_cast<std::uint64_t>(image.step) * image.height > image.data._length ||
      image.step < 4ull * image.width) {
    if (why != nullptr) {
      *why = "depth image '" + std::string(encoding) + "' " + std::to_string(image.width) + "x" +
             std::to_string(image.height) + " step " + std::to_string(image.step) + " (" +
             std::to_string(image.data._length) +
             " bytes): expected little-endian 32FC1 metres, step >= 4 x width";
    }
    return std::nullopt;
  }
  return DepthImageLayout{reinterpret_cast<const float*>(image.data._buffer),
                          static_cast<int>(image.width), static_cast<int>(image.height),
                          static_cast<int>(image.step / 4)};
}

}  // namespace avs::runtime
