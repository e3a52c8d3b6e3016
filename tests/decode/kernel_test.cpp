// The scalar, SSE2 and AVX2 pair updates give bit-identical Gray words, flags and depths, with
// per-pixel rays and with separable rays (a camera without distortion).
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/triangulation.hpp"
#include "rolling_kernel.hpp"
#include "subcode.hpp"

namespace avs::decode::detail {
namespace {

TEST(PairKernel, AllInstructionSetsAgree) {
  const SensorGeometry g = default_sensor_geometry();
  const DepthTable table(g);
  ASSERT_NE(table.column_ray_x(), nullptr) << "no distortion: separable rays";
  ASSERT_NE(table.row_ray_y(), nullptr);
  const int width = g.camera.width, height = g.camera.height, pixels = width * height;
  std::mt19937 random(3);
  std::uniform_int_distribution<int> byte(0, 255), word(0, 511);
  std::vector<std::uint8_t> positive(pixels), negative(pixels);
  std::vector<std::uint16_t> gray(pixels), valid(pixels);
  for (int i = 0; i < pixels; ++i) {
    positive[i] = static_cast<std::uint8_t>(byte(random));
    negative[i] = static_cast<std::uint8_t>(byte(random));
    gray[i] = static_cast<std::uint16_t>(word(random));
    valid[i] = static_cast<std::uint16_t>(word(random) | (i % 3 == 0 ? 511 : 0));
  }
  for (int bit_position : {8, 4, 0}) {
    std::vector<std::vector<std::uint16_t>> grays, valids;
    std::vector<std::vector<float>> depths;
    for (int variant = 0; variant < 6; ++variant) {
      const KernelIsa isa =
          std::array{KernelIsa::kScalar, KernelIsa::kSse2, KernelIsa::kAvx2}[variant % 3];
      const bool separable = variant >= 3;
      if (isa == KernelIsa::kAvx2 && best_kernel_isa() != KernelIsa::kAvx2) continue;
      grays.push_back(gray);
      valids.push_back(valid);
      depths.emplace_back(pixels, 0.0f);
      PairUpdateArgs a;
      a.positive = positive.data();
      a.positive_stride = width;
      a.negative = negative.data();
      a.negative_stride = width;
      a.width = width;
      a.height = height;
      a.gray = grays.back().data();
      a.valid = valids.back().data();
      a.bit_position = bit_position;
      a.threshold_psi = 10;
      a.code_correction = true;
      a.full_mask = 511;
      a.depth_m = depths.back().data();
      a.ray_x = table.ray_x();
      a.ray_y = table.ray_y();
      if (separable) {
        a.column_ray_x = table.column_ray_x();
        a.row_ray_y = table.row_ray_y();
      }
      a.planes = table.planes();
      a.invalid_index = table.invalid_index();
      a.min_depth_m = 0.05f;
      a.max_depth_m = 20.0f;
      update_pair(a, isa);
    }
    int valid_depths = 0;
    for (float z : depths[0]) valid_depths += !std::isnan(z);
    EXPECT_GT(valid_depths, 1000);
    for (std::size_t j = 1; j < grays.size(); ++j) {
      EXPECT_EQ(grays[j], grays[0]) << "isa " << j;
      EXPECT_EQ(valids[j], valids[0]) << "isa " << j;
      EXPECT_EQ(std::memcmp(depths[j].data(), depths[0].data(), sizeof(float) * pixels), 0)
          << "isa " << j;
    }
    // And the scalar result is what DepthTable::depth() gives for the updated word.
    for (int i = 0; i < pixels; i += 97) {
      const int code = static_cast<int>(gray_to_binary(grays[0][i]));
      const float expected = valids[0][i] == 511 ? table.depth(i, code) : NAN;
      const bool in_range = expected > 0.05f && expected < 20.0f;
      if (in_range) {
        EXPECT_EQ(depths[0][i], expected) << "pixel " << i;
      } else {
        EXPECT_TRUE(std::isnan(depths[0][i])) << "pixel " << i;
      }
    }
  }
}

TEST(PairKernel, BitsOnlyUpdateAgreesAcrossInstructionSets) {
  // depth_m = null (the window is not complete yet): Gray words and flags only; with codes (the
  // sub-code refinement's input) the binary codes as well, as codes_from_gray gives them.
  const int width = 77, height = 5, pixels = width * height;  // odd width: the scalar tail too
  std::mt19937 random(4);
  std::uniform_int_distribution<int> byte(0, 255), word(0, 511);
  std::vector<std::uint8_t> positive(pixels), negative(pixels);
  std::vector<std::uint16_t> gray(pixels), valid(pixels);
  for (int i = 0; i < pixels; ++i) {
    positive[i] = static_cast<std::uint8_t>(byte(random));
    negative[i] = static_cast<std::uint8_t>(byte(random));
    gray[i] = static_cast<std::uint16_t>(word(random));
    valid[i] = static_cast<std::uint16_t>(word(random) | (i % 3 == 0 ? 511 : 0));
  }
  constexpr int kCodeCount = 400;  // below 2^9: some complete words are no code
  for (const auto& [correction, with_codes] :
       {std::pair{true, false}, std::pair{false, false}, std::pair{true, true}}) {
    std::vector<std::vector<std::uint16_t>> grays, valids;
    std::vector<std::vector<std::int16_t>> codes;
    for (KernelIsa isa : {KernelIsa::kScalar, KernelIsa::kSse2, KernelIsa::kAvx2}) {
      if (isa == KernelIsa::kAvx2 && best_kernel_isa() != KernelIsa::kAvx2) continue;
      grays.push_back(gray);
      valids.push_back(valid);
      codes.emplace_back(pixels, std::int16_t{-7});
      PairUpdateArgs a;
      a.positive = positive.data();
      a.positive_stride = width;
      a.negative = negative.data();
      a.negative_stride = width;
      a.width = width;
      a.height = height;
      a.gray = grays.back().data();
      a.valid = valids.back().data();
      a.bit_position = 5;
      a.threshold_psi = 10;
      a.code_correction = correction;
      a.full_mask = 511;
      if (with_codes) {
        a.codes = codes.back().data();
        a.code_count = kCodeCount;
      }
      update_pair(a, isa);
    }
    EXPECT_NE(grays[0], gray);
    for (std::size_t j = 1; j < grays.size(); ++j) {
      EXPECT_EQ(grays[j], grays[0]) << "isa " << j;
      EXPECT_EQ(valids[j], valids[0]) << "isa " << j;
      EXPECT_EQ(codes[j], codes[0]) << "isa " << j;
    }
    if (!with_codes) {
      EXPECT_EQ(codes[0], std::vector<std::int16_t>(pixels, -7)) << "no codes asked, none written";
      continue;
    }
    std::vector<std::int16_t> expected(pixels);
    codes_from_gray(grays[0].data(), valids[0].data(), 511, kCodeCount, expected.data(), pixels);
    EXPECT_EQ(codes[0], expected);
    int coded = 0, complete_but_too_large = 0;
    for (int i = 0; i < pixels; ++i) {
      coded += expected[i] >= 0 ? 1 : 0;
      complete_but_too_large +=
          valids[0][i] == 511 && gray_to_binary(grays[0][i]) >= kCodeCount ? 1 : 0;
    }
    EXPECT_GT(coded, 0);
    EXPECT_GT(complete_but_too_large, 0) << "the code-count bound is exercised";
  }
}

TEST(PairKernel, DistortedCameraRaysAreNotSeparable) {
  SensorGeometry g = default_sensor_geometry();
  g.camera.k1 = -0.1;
  const DepthTable table(g);
  EXPECT_EQ(table.column_ray_x(), nullptr);
  EXPECT_EQ(table.row_ray_y(), nullptr);
}

}  // namespace
}  // namespace avs::decode::detail
