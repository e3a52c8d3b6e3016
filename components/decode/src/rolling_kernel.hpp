// The hot loop of the rolling decoder: one pair in, Gray words updated, depth out.
#pragma once

#include <cstddef>
#include <cstdint>

namespace avs::decode::detail {

struct PairUpdateArgs {
  const std::uint8_t* positive = nullptr;
  std::ptrdiff_t positive_stride = 0;
  const std::uint8_t* negative = nullptr;
  std::ptrdiff_t negative_stride = 0;
  int width = 0;
  int height = 0;
  std::uint16_t* gray = nullptr;   ///< width * height, updated in place
  std::uint16_t* valid = nullptr;  ///< width * height, updated in place
  int bit_position = 0;            ///< n - 1 - k
  int threshold_psi = 0;
  bool code_correction = false;
  std::uint16_t full_mask = 0;  ///< (1 << n) - 1
  /// Depth output; null to update the bits only.
  float* depth_m = nullptr;
  /// Without depth output: the binary code of every pixel as well (width * height, -1 unless
  /// every bit is known and the code is below code_count), for the sub-code refinement.
  std::int16_t* codes = nullptr;
  int code_count = 0;
  const float* ray_x = nullptr;
  const float* ray_y = nullptr;
  /// Optional, both or neither: separable rays (DepthTable::column_ray_x / row_ray_y), used
  /// instead of ray_x / ray_y when set; same values, so bit-identical results.
  const float* column_ray_x = nullptr;  ///< width floats
  const float* row_ray_y = nullptr;     ///< height floats
  const float* planes = nullptr;        ///< (a, b, c, 0) per binary code, NaN for invalid codes
  int invalid_index = 0;
  float min_depth_m = 0;
  float max_depth_m = 0;
};

enum class KernelIsa { kScalar, kSse2, kAvx2 };

/// AVX2 when the CPU has it (checked once at run time), else SSE2 (baseline x86-64), else scalar.
KernelIsa best_kernel_isa();
const char* kernel_isa_name(KernelIsa isa);

/// Eq. 2 binarisation of one pair, bit k written into every pixel's Gray word (with Algorithm 1
/// when enabled), Gray -> binary, and depth = 1 / (a x + b y + c) from the tables.
void update_pair(const PairUpdateArgs& args);
/// Same with a given instruction set (all give bit-identical results).
void update_pair(const PairUpdateArgs& args, KernelIsa isa);

}  // namespace avs::decode::detail
