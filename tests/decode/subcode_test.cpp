// Sub-code refinement (components/decode/src/subcode.hpp) on synthetic code staircases.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

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

// The refiner's definition written the slow way, one pixel at a time: the window's valid codes
// enumerated, each one's discontinuity flag found by walking up its column, the line fit from
// 64-bit sums about the pixel (d = y - y0) and the same float division as the refiner.
std::vector<float> refine_by_definition(const std::vector<std::int16_t>& codes, int width,
                                        int height, int half, int max_jump) {
  const auto code_at = [&](int x, int y) { return codes[static_cast<std::size_t>(y) * width + x]; };
  const auto jump_at = [&](int x, int y) {
    if (code_at(x, y) < 0) return false;
    for (int above = y - 1; above >= 0; --above) {
      if (code_at(x, above) < 0) continue;
      const int gap = y - above;
      return gap <= 2 * half && std::abs(code_at(x, y) - code_at(x, above)) > max_jump * gap;
    }
    return false;
  };
  std::vector<float> refined(codes.size(), std::numeric_limits<float>::quiet_NaN());
  for (int y0 = 0; y0 < height; ++y0) {
    for (int x = 0; x < width; ++x) {
      const int c0 = code_at(x, y0);
      if (c0 < 0) continue;
      std::int64_t n = 0, sd = 0, sdd = 0, sc = 0, scd = 0;
      bool jump = false;
      for (int y = std::max(0, y0 - half); y <= std::min(height - 1, y0 + half); ++y) {
        const int c = code_at(x, y);
        if (c < 0) continue;
        const int d = y - y0;
        n += 1;
        sd += d;
        sdd += d * d;
        sc += c;
        scd += c * d;
        jump = jump || jump_at(x, y);
      }
      const std::int64_t det = n * sdd - sd * sd;
      const auto c = static_cast<float>(c0);
      float u = c;
      if (!jump && n >= 3 && det > 0) {
        const float intercept =
            sd == 0 ? static_cast<float>(sc) / static_cast<float>(n)  // the mean
                    : static_cast<float>(sc * sdd - scd * sd) / static_cast<float>(det);
        u = std::min(std::max(intercept, c - 1.0f), c + 1.0f);
      }
      refined[static_cast<std::size_t>(y0) * width + x] = u;
    }
  }
  return refined;
}

// The sliding-window refiner (running sums; plain and AVX2) equals its definition bit for bit on
// noisy staircases with holes and discontinuities, for every window size; widths that leave a
// remainder after the 8-column blocks; a window taller than the image.
TEST(SubcodeRefiner, EqualsTheFitWrittenPixelByPixel) {
  std::mt19937 random(11);
  int narrow_runs = 0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Codes of a few hundred, then (half > 0) codes up to the largest the 16-bit sums of that
  // half window allow, (2h + 1)(largest + 1) and h (h + 1) largest below 2^15, so that those
  // sums come near their limits.
  struct Field {
    int width, height, half;
  };
  for (const Field field : {Field{37, 90, 0}, Field{16, 7, 0}, Field{46, 60, 0}, Field{37, 60, 1},
                            Field{37, 60, 4}, Field{46, 60, 7}, Field{37, 60, 16}}) {
    const int width = field.width;
    const int height = field.height;
    const int largest = field.half > 0 ? std::min(32767 / (2 * field.half + 1) - 1,
                                                  32767 / (field.half * (field.half + 1)))
                                       : 0;
    std::vector<std::int16_t> codes(static_cast<std::size_t>(width) * height);
    for (int x = 0; x < width; ++x) {
      double f = largest > 0 ? largest - 60.0 + x : 40.0 + 3.0 * x;
      const double slope = 0.1 + 0.9 * unit(random);
      for (int y = 0; y < height; ++y) {
        f += slope + (unit(random) < 0.03 ? 30.0 * (unit(random) - 0.5) : 0.0);
        const double noisy = f + 0.4 * (unit(random) - 0.5);
        codes[static_cast<std::size_t>(y) * width + x] =
            unit(random) < 0.12 ? std::int16_t{-1}
                                : quantise(std::clamp(noisy, 0.0, largest > 0 ? largest : 32767.0));
      }
    }
    // With the largest code known the AVX2 step takes 16-bit sums where they are exact (half
    // windows up to 7 here), without it 32-bit ones.
    const int code_count = *std::max_element(codes.begin(), codes.end()) + 1;
    std::vector<std::pair<KernelIsa, int>> configurations{{KernelIsa::kScalar, code_count}};
    if (best_kernel_isa() == KernelIsa::kAvx2) {
      configurations.emplace_back(KernelIsa::kAvx2, 0);
      configurations.emplace_back(KernelIsa::kAvx2, code_count);
    }
    int field_narrow_runs = 0;
    const std::vector<int> halves =
        field.half > 0 ? std::vector<int>{field.half} : std::vector<int>{1, 2, 4, 7, 16};
    for (const int half : halves) {
      // 40000 and 65536: beyond the 16-bit factors of the AVX2 steps' products (clamped).
      for (const int max_jump : {0, 2, 5, 40000, 65536}) {
        const std::vector<float> expected =
            refine_by_definition(codes, width, height, half, max_jump);
        for (const auto& [isa, code_count] : configurations) {
          SubcodeRefiner refiner({width, height, half, max_jump, code_count}, isa);
          narrow_runs += refiner.narrow_sums() ? 1 : 0;
          field_narrow_runs += refiner.narrow_sums() ? 1 : 0;
          std::vector<float> refined(codes.size());
          refiner.refine(codes.data(), refined.data());
          int refined_pixels = 0;
          for (std::size_t i = 0; i < codes.size(); ++i) {
            refined_pixels += codes[i] >= 0 && refined[i] != static_cast<float>(codes[i]) ? 1 : 0;
          }
          if (height > 2 * half && max_jump >= 2) {  // 0: every code change is a jump
            EXPECT_GT(refined_pixels, 0) << "half " << half;
          }
          ASSERT_EQ(std::memcmp(refined.data(), expected.data(), refined.size() * sizeof(float)), 0)
              << kernel_isa_name(isa) << ", code count " << code_count << ", " << width << "x"
              << height << ", half window " << half << ", max jump " << max_jump;
        }
      }
    }
    if (field.half > 0 && best_kernel_isa() == KernelIsa::kAvx2) {
      EXPECT_GT(field_narrow_runs, 0) << "codes up to " << largest << " with half window "
                                      << field.half << " take the 16-bit sums";
    }
  }
  EXPECT_GT(narrow_runs, 0) << "the 16-bit sums were compared too";
}

// What the AVX2 step relies on to take the mean of a complete window without a division: for
// an odd window of n rows (3 .. 33) and every possible code sum (codes are int16), sc * (1 / n)
// in double, rounded to float, is the float division sc / n bit for bit.
TEST(SubcodeRefiner, TheMeanByAReciprocalIsTheFloatDivision) {
  for (int n = 3; n <= 33; n += 2) {
    const double inverse = 1.0 / n;
    int differing = 0;
    for (std::int32_t sc = 0; sc <= n * 32767; ++sc) {
      const float divided = static_cast<float>(sc) / static_cast<float>(n);
      const auto multiplied = static_cast<float>(static_cast<double>(sc) * inverse);
      differing += divided != multiplied ? 1 : 0;
    }
    EXPECT_EQ(differing, 0) << "window of " << n << " rows";
  }
}

TEST(SubcodeRefiner, RejectsBadParameters) {
  EXPECT_THROW(SubcodeRefiner({kWidth, kHeight, 0, 2}), std::invalid_argument);
  EXPECT_THROW(SubcodeRefiner({kWidth, kHeight, 17, 2}), std::invalid_argument);
  EXPECT_THROW(SubcodeRefiner({kWidth, kHeight, 4, -1}), std::invalid_argument);
  SubcodeRefiner refiner({kWidth, kHeight, 4, 2});
  std::vector<std::int16_t> codes(kWidth * kHeight, 3);
  std::vector<float> row(kWidth);
  EXPECT_THROW(
      refiner.refine(codes.data(), row.data(), nullptr, SubcodeRefiner::RefinedRows::kOneRowForAll),
      std::invalid_argument)
      << "one row for all without a sink would lose every row but the last";
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
  ASSERT_NE(table.linear_subcode_planes(), nullptr) << "no projector distortion";
  // The table of planes and the planes in closed form (the decoder's choice without projector
  // distortion).
  for (const bool linear : {false, true}) {
    const SubcodePlanes planes{table.subcode_planes(), table.subcode_steps(),
                               table.subcode_plane_count(),
                               linear ? table.linear_subcode_planes() : nullptr};
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
    // Row by row with separable rays (the decoder's way for a camera without distortion): the
    // same depths as with the per-pixel rays.
    ASSERT_NE(table.column_ray_x(), nullptr);
    std::vector<float> per_pixel(static_cast<std::size_t>(pixels));
    triangulate_subcode(refined.data(), planes, table.ray_x(), table.ray_y(), 0.3f, 1.5f,
                        per_pixel.data(), pixels, KernelIsa::kScalar);
    for (const KernelIsa isa : {KernelIsa::kScalar, best_kernel_isa()}) {
      std::vector<float> by_row(static_cast<std::size_t>(pixels));
      for (int y = 0; y < g.camera.height; ++y) {
        const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(y) * g.camera.width;
        triangulate_subcode_row(refined.data() + offset, planes, table.column_ray_x(),
                                table.row_ray_y()[y], 0.3f, 1.5f, by_row.data() + offset,
                                g.camera.width, isa);
      }
      EXPECT_EQ(std::memcmp(per_pixel.data(), by_row.data(), by_row.size() * sizeof(float)), 0)
          << kernel_isa_name(isa) << (linear ? ", planes in closed form" : ", table");
    }
  }
}

// The planes in closed form are Eq. 4's: at every code centre (u = code) their depth equals the
// 3x3 solve of ReferenceTriangulator (double) to float precision, for the paper's sensor and
// for a projector turned and moved off the paper's baseline; and the table's nearest sub-code
// plane differs from them by no more than its 1/16-code step explains.
TEST(SubcodeTriangulation, PlanesInClosedFormAreEq4s) {
  SensorGeometry turned = default_sensor_geometry();
  turned.R_projector_camera =
      (Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()) * turned.R_projector_camera).eval();
  turned.t_projector_camera_m += Eigen::Vector3d(0.03, -0.01, 0.02);
  for (const SensorGeometry& g : {default_sensor_geometry(), turned}) {
    const DepthTable table(g, 16);
    const ReferenceTriangulator reference(g);
    ASSERT_NE(table.linear_subcode_planes(), nullptr);
    const SubcodePlanes linear{table.subcode_planes(), table.subcode_steps(),
                               table.subcode_plane_count(), table.linear_subcode_planes()};
    const SubcodePlanes tabled{table.subcode_planes(), table.subcode_steps(),
                               table.subcode_plane_count()};
    int compared = 0;
    double worst_relative = 0;
    for (int i = 0; i < g.camera.width * g.camera.height; i += 211) {
      for (int code = 0; code < g.layout.code_count; code += 3) {
        const double z_reference = reference.point(i, code).z();
        if (!(z_reference > 0.3 && z_reference < 3.0)) continue;
        const float u = static_cast<float>(code);
        float z = 0;
        triangulate_subcode(&u, linear, table.ray_x() + i, table.ray_y() + i, 0.1f, 10.0f, &z, 1);
        worst_relative = std::max(worst_relative, std::abs(z - z_reference) / z_reference);
        ++compared;
        // Off the code centre by a third of the table's step: the table keeps the centre's plane.
        const float off = u + 1.0f / 48;
        float z_linear = 0, z_table = 0;
        triangulate_subcode(&off, linear, table.ray_x() + i, table.ray_y() + i, 0.1f, 10.0f,
                            &z_linear, 1);
        triangulate_subcode(&off, tabled, table.ray_x() + i, table.ray_y() + i, 0.1f, 10.0f,
                            &z_table, 1);
        EXPECT_NE(z_linear, z_table);
        EXPECT_NEAR(z_table, z, 1e-5 * z) << "the table's plane is the centre's";
      }
    }
    EXPECT_GT(compared, 1000);
    EXPECT_LT(worst_relative, 5e-6) << "float precision of the closed form (5 um at 1 m)";
    std::printf("closed form vs Eq. 4 solve: %d depths, worst relative difference %.2e\n", compared,
                worst_relative);
  }
  SensorGeometry distorted = default_sensor_geometry();
  distorted.projector.k1 = -0.05;
  EXPECT_EQ(DepthTable(distorted, 16).linear_subcode_planes(), nullptr)
      << "with projector distortion the rows are not planes: the fitted table";
}

}  // namespace
}  // namespace avs::decode::detail
