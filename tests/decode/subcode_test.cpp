// Sub-code refinement (components/decode/src/subcode.hpp) on synthetic code staircases.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/triangulation.hpp"
#include "subcode.hpp"

namespace avs::decode::detail {
namespace {

constexpr int kWidth = 8;
constexpr int kHeight = 200;

// Code c covers the projector coordinate f in [c - 1/2, c + 1/2).
std::int16_t quantise(double f) {
  return static_cast<std::int16_t>(std::floor(f + 0.5));
}

struct Column {
  std::vector<std::int16_t> codes;
  std::vector<double> truth;
};

// Every column the same staircase f(y) = slope y + offset (+ jump below row jump_row).
Column staircase(double slope, double offset, int jump_row = kHeight, double jump = 0) {
  Column c;
  for (int y = 0; y < kHeight; ++y) {
    const double f = slope * y + offset + (y >= jump_row ? jump : 0.0);
    for (int x = 0; x < kWidth; ++x) {
      c.codes.push_back(quantise(f + 0.01 * x));
      c.truth.push_back(f + 0.01 * x);
    }
  }
  return c;
}

double rms_error(const Column& c, const std::vector<float>& refined, int y0, int y1, bool plain) {
  double sum = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * kWidth + x;
      if (c.codes[i] < 0) continue;
      const double value = plain ? c.codes[i] : refined[i];
      sum += (value - c.truth[i]) * (value - c.truth[i]);
      ++n;
    }
  }
  return std::sqrt(sum / n);
}

TEST(SubcodeRefiner, LineFitRemovesMostOfTheQuantisation) {
  for (double slope : {0.25, 0.43, 0.8}) {
    const Column c = staircase(slope, 10.2);
    SubcodeRefiner refiner({kWidth, kHeight, 4, 2});
    std::vector<float> refined(c.codes.size());
    refiner.refine(c.codes.data(), refined.data());
    const double plain = rms_error(c, refined, 4, kHeight - 4, true);
    const double fitted = rms_error(c, refined, 4, kHeight - 4, false);
    std::printf("slope %.2f codes/row: code-centre RMS %.3f codes, refined %.3f codes\n", slope,
                plain, fitted);
    EXPECT_NEAR(plain, 1.0 / std::sqrt(12.0), 0.05);
    EXPECT_LT(fitted, 0.4 * plain);
  }
}

TEST(SubcodeRefiner, DiscontinuityKeepsThePlainCode) {
  const Column c = staircase(0.43, 10.2, 100, 60.0);
  SubcodeRefiner refiner({kWidth, kHeight, 4, 2});
  std::vector<float> refined(c.codes.size());
  refiner.refine(c.codes.data(), refined.data());
  for (int y = 90; y < 110; ++y) {
    const std::size_t i = static_cast<std::size_t>(y) * kWidth;
    if (std::abs(y - 100) <= 3) {
      EXPECT_EQ(refined[i], static_cast<float>(c.codes[i])) << "row " << y;
    }
    EXPECT_LE(std::abs(refined[i] - c.codes[i]), 1.0F) << "row " << y;
  }
  // Away from the jump both sides are refined.
  EXPECT_LT(rms_error(c, refined, 10, 90, false), 0.35 * rms_error(c, refined, 10, 90, true));
  EXPECT_LT(rms_error(c, refined, 110, 190, false), 0.35 * rms_error(c, refined, 110, 190, true));
}

TEST(SubcodeRefiner, InvalidPixelsStayInvalidAndGapsAreTolerated) {
  Column c = staircase(0.43, 10.2);
  for (int y = 0; y < kHeight; y += 5) {
    for (int x = 0; x < kWidth; ++x) c.codes[static_cast<std::size_t>(y) * kWidth + x] = -1;
  }
  SubcodeRefiner refiner({kWidth, kHeight, 4, 2});
  std::vector<float> refined(c.codes.size());
  refiner.refine(c.codes.data(), refined.data());
  for (std::size_t i = 0; i < c.codes.size(); ++i) {
    EXPECT_EQ(std::isnan(refined[i]), c.codes[i] < 0) << "pixel " << i;
  }
  EXPECT_LT(rms_error(c, refined, 4, kHeight - 4, false),
            0.4 * rms_error(c, refined, 4, kHeight - 4, true));
}

TEST(SubcodeRefiner, RejectsBadParameters) {
  EXPECT_THROW(SubcodeRefiner({kWidth, kHeight, 0, 2}), std::invalid_argument);
  EXPECT_THROW(SubcodeRefiner({kWidth, kHeight, 17, 2}), std::invalid_argument);
  EXPECT_THROW(SubcodeRefiner({kWidth, kHeight, 4, -1}), std::invalid_argument);
}

// The AVX2 triangulation (8 pixels, plane rows loaded and transposed) equals the plain loop bit
// for bit: codes across the table, between its planes, outside it, NaN; depths in and out of
// the window.
TEST(SubcodeTriangulation, InstructionSetsGiveBitIdenticalDepths) {
  if (best_kernel_isa() != KernelIsa::kAvx2) GTEST_SKIP() << "this CPU has no AVX2";
  const SensorGeometry g = default_sensor_geometry();
  const DepthTable table(g, 16);
  const int pixels = g.camera.width * g.camera.height;
  std::mt19937 random(5);
  std::uniform_real_distribution<float> code(-3.0f, static_cast<float>(g.layout.code_count) + 3);
  std::vector<float> refined(static_cast<std::size_t>(pixels));
  for (int i = 0; i < pixels; ++i) {
    refined[static_cast<std::size_t>(i)] =
        i % 17 == 0 ? std::numeric_limits<float>::quiet_NaN() : code(random);
  }
  const SubcodePlanes planes{table.subcode_planes(), table.subcode_steps(),
                             table.subcode_plane_count()};
  // Odd pixel counts leave a tail for the plain loop after the 8-pixel blocks.
  for (const int n : {pixels, pixels - 5}) {
    for (const auto& [min_m, max_m] : {std::pair{0.3f, 1.5f}, std::pair{0.9f, 1.1f}}) {
      std::vector<float> plain(static_cast<std::size_t>(n)), avx2(static_cast<std::size_t>(n));
      triangulate_subcode(refined.data(), planes, table.ray_x(), table.ray_y(), min_m, max_m,
                          plain.data(), n, KernelIsa::kScalar);
      triangulate_subcode(refined.data(), planes, table.ray_x(), table.ray_y(), min_m, max_m,
                          avx2.data(), n, KernelIsa::kAvx2);
      int finite = 0;
      for (const float z : plain) finite += std::isfinite(z) ? 1 : 0;
      EXPECT_GT(finite, 100) << "some codes fall in the table and the window";
      EXPECT_EQ(std::memcmp(plain.data(), avx2.data(), plain.size() * sizeof(float)), 0)
          << n << " pixels, window " << min_m << ".." << max_m << " m";
    }
  }
}

}  // namespace
}  // namespace avs::decode::detail
