// Section 4.4, Algorithm 1, Table 4.
#include <gtest/gtest.h>

#include "avs/decode/rolling_decoder.hpp"

namespace avs::decode {
namespace {

TEST(CodeCorrection, PaperFourBitExample) {
  // Table 4: 3 = 0010. At step k+1 the MSB changes to 1.
  const std::uint32_t before = 0b0010;
  ASSERT_EQ(gray_to_binary(before), 3u);
  // Without correction the stale lower bits make it 1010 = 12, far from the 7/8 boundary.
  const std::uint32_t uncorrected = (before & ~0b1000u) | 0b1000u;
  EXPECT_EQ(gray_to_binary(uncorrected), 12u);
  // Algorithm 1: g_1 -> 1, g_2, g_3 -> 0: 1100 = 8, next to the boundary 0100 = 7 / 1100 = 8.
  const std::uint32_t corrected = update_gray_with_correction(before, 0, 1, 4);
  EXPECT_EQ(corrected, 0b1100u);
  EXPECT_EQ(gray_to_binary(corrected), 8u);
}

TEST(CodeCorrection, UnchangedBitLeavesLowerBitsAlone) {
  EXPECT_EQ(update_gray_with_correction(0b1010, 0, 1, 4), 0b1010u);
  EXPECT_EQ(update_gray_with_correction(0b0110, 2, 1, 4), 0b0110u);
  // LSB change: nothing below it.
  EXPECT_EQ(update_gray_with_correction(0b0110, 3, 1, 4), 0b0111u);
  // Bit 1 changes in 0110: 0 -> bit 1 is 1 ... here 0110 bit 1 (from MSB) is 1, set to 0:
  // 0010, then bit 2 -> 1, bit 3 -> 0: 0010.
  EXPECT_EQ(update_gray_with_correction(0b0110, 1, 0, 4), 0b0010u);
}

// The same example through the rolling decoder's vectorised kernel: one 4-bit sensor, a row of
// pixels that first see code 3, then the MSB pair of the next cycle says 1.
class CorrectionInDecoder : public ::testing::TestWithParam<bool> {};

TEST_P(CorrectionInDecoder, MsbFlipKeepsCodeNearBoundary) {
  const bool correction = GetParam();
  DecoderConfig config;
  config.geometry.layout = CodeLayout{4, 16, 64, 60};
  config.geometry.camera.width = 16;
  config.geometry.camera.height = 2;
  config.geometry.camera.cx_px = 7.5;
  config.geometry.camera.cy_px = 0.5;
  config.code_correction = correction;
  config.min_depth_m = -1e9f;
  config.max_depth_m = 1e9f;
  RollingDecoder decoder(config);
  const int pixels = 32;
  std::vector<std::uint8_t> on(pixels, 200), off(pixels, 20);
  const ImageView8 on_view{on.data(), 16, 2, 16}, off_view{off.data(), 16, 2, 16};
  // Cycle 0: Gray 0010 = 3.
  const int gray3[4] = {0, 0, 1, 0};
  for (int k = 0; k < 4; ++k) {
    decoder.push_pair(gray3[k] ? on_view : off_view, gray3[k] ? off_view : on_view, k, 0);
  }
  ASSERT_EQ(decoder.code_map()[0], 3);
  // Cycle 1, bit 0 (MSB) now 1.
  decoder.push_pair(on_view, off_view, 0, 1);
  const int expected = correction ? 8 : 12;
  for (int code : decoder.code_map()) EXPECT_EQ(code, expected);
}

INSTANTIATE_TEST_SUITE_P(OnOff, CorrectionInDecoder, ::testing::Bool());

}  // namespace
}  // namespace avs::decode
