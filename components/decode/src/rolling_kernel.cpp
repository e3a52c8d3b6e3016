#include "rolling_kernel.hpp"

#include <limits>

namespace avs::decode::detail {
namespace {

// One image row; written as a branch-free loop over plain arrays so that the compiler
// vectorises it (the plane look-up is a gather of 3 floats).
template <bool kWithDepth>
void update_row(const std::uint8_t* __restrict positive, const std::uint8_t* __restrict negative,
                std::uint16_t* __restrict gray, std::uint16_t* __restrict valid,
                float* __restrict depth, const float* __restrict ray_x,
                const float* __restrict ray_y, const PairUpdateArgs& a) {
  const int position = a.bit_position;
  const int psi = a.threshold_psi;
  const auto bit_mask = static_cast<std::uint16_t>(1u << position);
  const auto lower_mask = static_cast<std::uint16_t>(bit_mask - 1u);
  const auto forced = static_cast<std::uint16_t>(bit_mask >> 1);  // Algorithm 1: 100..0
  const std::uint16_t correction = a.code_correction ? 0xffffu : 0u;
  const std::uint16_t full = a.full_mask;
  const int invalid = a.invalid_index;
  const float* __restrict planes = a.planes;
  const float zmin = a.min_depth_m;
  const float zmax = a.max_depth_m;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int x = 0; x < a.width; ++x) {
    // Eq. 2.
    const int difference = static_cast<int>(positive[x]) - static_cast<int>(negative[x]);
    const auto one = static_cast<std::uint16_t>(difference > psi);
    const auto known = static_cast<std::uint16_t>(one | (difference < -psi));
    std::uint16_t g = gray[x];
    std::uint16_t v = valid[x];
    // Algorithm 1: the bit changed between cycles (old and new both known).
    const auto changed =
        static_cast<std::uint16_t>(((g >> position) ^ one) & (v >> position) & known & 1u);
    const auto correct = static_cast<std::uint16_t>((0u - changed) & correction);
    g = static_cast<std::uint16_t>((g & ~bit_mask) | (one << position));
    g = static_cast<std::uint16_t>((g & ~(lower_mask & correct)) | (forced & correct));
    v = static_cast<std::uint16_t>((v & ~bit_mask) | (known << position));
    gray[x] = g;
    valid[x] = v;
    if constexpr (!kWithDepth) continue;
    // Eq. 3 word -> binary code.
    std::uint16_t b = static_cast<std::uint16_t>(g ^ (g >> 1));
    b = static_cast<std::uint16_t>(b ^ (b >> 2));
    b = static_cast<std::uint16_t>(b ^ (b >> 4));
    b = static_cast<std::uint16_t>(b ^ (b >> 8));
    const int index = v == full ? b : invalid;
    const float* plane = planes + 4 * index;
    const float z = 1.0f / (plane[0] * ray_x[x] + plane[1] * ray_y[x] + plane[2]);
    depth[x] = (z > zmin && z < zmax) ? z : nan;
  }
}

}  // namespace

void update_pair(const PairUpdateArgs& a) {
  for (int y = 0; y < a.height; ++y) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * a.width;
    const auto* positive = a.positive + y * a.positive_stride;
    const auto* negative = a.negative + y * a.negative_stride;
    if (a.depth_m == nullptr) {
      update_row<false>(positive, negative, a.gray + row, a.valid + row, nullptr, nullptr, nullptr,
                        a);
    } else {
      update_row<true>(positive, negative, a.gray + row, a.valid + row, a.depth_m + row,
                       a.ray_x + row, a.ray_y + row, a);
    }
  }
}

}  // namespace avs::decode::detail
