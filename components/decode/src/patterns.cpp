#include "avs/decode/patterns.hpp"

#include <stdexcept>
#include <string>

namespace avs::decode {

std::vector<PatternImage> make_patterns(const CodeLayout& layout, int width, int height) {
  if (width <= 0 || height <= 0 || layout.bit_count < 1 || layout.bit_count > 15 ||
      layout.code_count > (1 << layout.bit_count)) {
    throw std::invalid_argument("make_patterns: invalid projector size " + std::to_string(width) +
                                "x" + std::to_string(height) + " or code layout (" +
                                std::to_string(layout.bit_count) + " bits, " +
                                std::to_string(layout.code_count) + " codes)");
  }
  std::vector<PatternImage> patterns;
  patterns.reserve(2 * layout.bit_count);
  for (int k = 0; k < layout.bit_count; ++k) {
    for (Polarity polarity : {Polarity::kPositive, Polarity::kNegative}) {
      PatternImage image{k, polarity, width, height, {}};
      image.pixels.resize(static_cast<std::size_t>(width) * height);
      for (int row = 0; row < height; ++row) {
        const auto value = static_cast<std::uint8_t>(255 * pattern_value(layout, row, k, polarity));
        std::fill_n(image.pixels.begin() + static_cast<std::ptrdiff_t>(row) * width, width, value);
      }
      patterns.push_back(std::move(image));
    }
  }
  return patterns;
}

}  // namespace avs::decode
