#include <bit>
#include <cmath>

#include <gtest/gtest.h>

#include "avs/decode/patterns.hpp"

namespace avs::decode {
namespace {

TEST(GrayCode, NeighbouringCodesDifferInExactlyOneBit) {
  const CodeLayout layout;  // 9 bits, 265 codes
  for (std::uint32_t code = 0; code + 1 < (1u << layout.bit_count); ++code) {
    int differing_bits = 0;
    for (int k = 0; k < layout.bit_count; ++k) {
      differing_bits += gray_bit(layout, code, k) != gray_bit(layout, code + 1, k);
    }
    EXPECT_EQ(differing_bits, 1) << "codes " << code << " and " << code + 1;
    EXPECT_EQ(std::popcount(binary_to_gray(code) ^ binary_to_gray(code + 1)), 1);
    EXPECT_EQ(gray_to_binary(binary_to_gray(code)), code);
  }
}

TEST(Patterns, ProjectionOrderPolarityAndRows) {
  CodeLayout layout;
  layout.first_row = 40;
  const int width = 912, height = 1140;
  const auto patterns = make_patterns(layout, width, height);
  ASSERT_EQ(patterns.size(), 2u * layout.bit_count);
  for (int k = 0; k < layout.bit_count; ++k) {
    const PatternImage& positive = patterns[2 * k];
    const PatternImage& negative = patterns[2 * k + 1];
    EXPECT_EQ(positive.bit_index, k);
    EXPECT_EQ(positive.polarity, Polarity::kPositive);
    EXPECT_EQ(negative.bit_index, k);
    EXPECT_EQ(negative.polarity, Polarity::kNegative);
    for (int row = 0; row < height; ++row) {
      const int code = code_of_row(layout, row);
      const std::uint8_t p = positive.pixels[static_cast<std::size_t>(row) * width + width / 2];
      const std::uint8_t n = negative.pixels[static_cast<std::size_t>(row) * width + width / 2];
      if (code < 0) {
        EXPECT_EQ(p, 0) << "row " << row;
        EXPECT_EQ(n, 0) << "row " << row;
        continue;
      }
      // Eq. 1 through the Gray code of the row's code; the negative is the complement.
      const int expected = static_cast<int>(
          (binary_to_gray(static_cast<std::uint32_t>(code)) >> (layout.bit_count - 1 - k)) & 1u);
      EXPECT_EQ(p, 255 * expected) << "row " << row << " bit " << k;
      EXPECT_EQ(n, 255 * (1 - expected)) << "row " << row << " bit " << k;
    }
  }
}

TEST(Patterns, MatchesEq1WhenCodesFillThePattern) {
  // Eq. 1 with P_y = 2^n * rows_per_code: P(y, k) = floor(y 2^k / P_y + 1/2) mod 2.
  const CodeLayout layout{9, 512, 2, 0};
  const int p_y = 512 * 2;
  for (int k = 0; k < layout.bit_count; ++k) {
    for (int y = 0; y < p_y; ++y) {
      const long eq1 =
          static_cast<long>(std::floor(static_cast<double>(y) * (1 << k) / p_y + 0.5)) % 2;
      ASSERT_EQ(pattern_bit(layout, y, k), eq1) << "row " << y << " bit " << k;
    }
  }
}

TEST(Patterns, RejectsInvalidLayout) {
  CodeLayout layout{9, 600, 2, 0};  // 600 codes do not fit in 9 bits
  EXPECT_THROW(make_patterns(layout, 10, 10), std::invalid_argument);
}

}  // namespace
}  // namespace avs::decode
