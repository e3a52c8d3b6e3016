// Pattern images of Eq. 1 (section 4.1) in projection order: bit 0 (MSB) positive, bit 0
// negative, bit 1 positive, ... Rows outside the coded range are dark in both polarities.
#pragma once

#include <cstdint>
#include <vector>

#include "avs/decode/gray_code.hpp"

namespace avs::decode {

enum class Polarity : std::uint8_t { kPositive = 0, kNegative = 1 };

/// 8-bit image, row-major, `width * height` bytes, values 0 or 255.
struct PatternImage {
  int bit_index = 0;
  Polarity polarity = Polarity::kPositive;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
};

/// Value (0 or 1) of projector row `row_p` in the pattern of bit k with the given polarity.
inline int pattern_value(const CodeLayout& layout, int row_p, int k, Polarity polarity) {
  if (code_of_row(layout, row_p) < 0) return 0;
  const int bit = pattern_bit(layout, row_p, k);
  return polarity == Polarity::kPositive ? bit : 1 - bit;
}

/// The 2n patterns for a projector of width x height pixels, in projection order.
std::vector<PatternImage> make_patterns(const CodeLayout& layout, int width, int height);

}  // namespace avs::decode
