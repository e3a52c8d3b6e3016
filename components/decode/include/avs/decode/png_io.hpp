// 8-bit grayscale PNG files (libpng), for `avs patterns` and its test. Kept out of the core.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace avs::decode {

struct GrayImage8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  ///< row-major, width * height
};

/// Writes `image` as an 8-bit grayscale PNG; throws std::runtime_error naming the file.
void write_png_gray8(const std::string& path, const GrayImage8& image);
/// Reads an 8-bit grayscale PNG (other formats are errors); throws std::runtime_error.
GrayImage8 read_png_gray8(const std::string& path);

}  // namespace avs::decode
