#include "rolling_kernel.hpp"

#include "plane_lookup_avx2.hpp"

#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define AVS_DECODE_X86 1
#endif

namespace avs::decode::detail {
namespace {

// One image row; written as a branch-free loop over plain arrays so that the compiler
// vectorises it (the plane look-up is a gather of 3 floats). kCodes (without depth): the binary
// codes of the row as well (PairUpdateArgs::codes, the row at the same offset as `gray`).
template <bool kWithDepth, bool kRowRay = false, bool kCodes = false>
void update_row(const std::uint8_t* __restrict positive, const std::uint8_t* __restrict negative,
                std::uint16_t* __restrict gray, std::uint16_t* __restrict valid,
                float* __restrict depth, const float* __restrict ray_x,
                const float* __restrict ray_y, const PairUpdateArgs& a, int begin = 0) {
  static_assert(!(kWithDepth && kCodes));
  std::int16_t* __restrict codes = kCodes ? a.codes + (gray - a.gray) : nullptr;
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
  for (int x = begin; x < a.width; ++x) {
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
    if constexpr (!kWithDepth && !kCodes) continue;
    // Eq. 3 word -> binary code.
    std::uint16_t b = static_cast<std::uint16_t>(g ^ (g >> 1));
    b = static_cast<std::uint16_t>(b ^ (b >> 2));
    b = static_cast<std::uint16_t>(b ^ (b >> 4));
    b = static_cast<std::uint16_t>(b ^ (b >> 8));
    if constexpr (kCodes) {
      codes[x] = static_cast<std::int16_t>(v == full && b < a.code_count ? b : -1);
      continue;
    }
    const int index = v == full ? b : invalid;
    const float* plane = planes + 4 * index;
    const float z = 1.0f / (plane[0] * ray_x[x] + plane[1] * ray_y[kRowRay ? 0 : x] + plane[2]);
    depth[x] = (z > zmin && z < zmax) ? z : nan;
  }
}

#if defined(AVS_DECODE_X86)
// The same row update with SSE2 (baseline x86-64), 8 pixels per step. The plane look-up is 4
// unaligned loads of (a, b, c, 0) and a 4x4 transpose per 4 pixels; the arithmetic order is the
// scalar one, so results are bit-identical to update_row(). kRowRay: ray_y is one value for
// the row (a camera without distortion, DepthTable::row_ray_y()).
template <bool kRowRay>
void update_row_sse2(const std::uint8_t* __restrict positive,
                     const std::uint8_t* __restrict negative, std::uint16_t* __restrict gray,
                     std::uint16_t* __restrict valid, float* __restrict depth,
                     const float* __restrict ray_x, const float* __restrict ray_y,
                     const PairUpdateArgs& a) {
  const auto bit_mask = static_cast<std::uint16_t>(1u << a.bit_position);
  const __m128i zero = _mm_setzero_si128();
  const __m128i psi = _mm_set1_epi16(static_cast<short>(a.threshold_psi));
  const __m128i minus_psi = _mm_set1_epi16(static_cast<short>(-a.threshold_psi));
  const __m128i bit = _mm_set1_epi16(static_cast<short>(bit_mask));
  const __m128i lower = _mm_set1_epi16(static_cast<short>(bit_mask - 1u));
  const __m128i forced = _mm_set1_epi16(static_cast<short>(bit_mask >> 1));
  const __m128i correction = _mm_set1_epi16(a.code_correction ? static_cast<short>(-1) : 0);
  const __m128i full = _mm_set1_epi16(static_cast<short>(a.full_mask));
  const __m128i invalid = _mm_set1_epi16(static_cast<short>(a.invalid_index));
  const __m128 zmin = _mm_set1_ps(a.min_depth_m);
  const __m128 zmax = _mm_set1_ps(a.max_depth_m);
  const __m128 one = _mm_set1_ps(1.0f);
  const __m128 nan = _mm_set1_ps(std::numeric_limits<float>::quiet_NaN());
  const float* planes = a.planes;
  int x = 0;
  for (; x + 8 <= a.width; x += 8) {
    // Eq. 2.
    const __m128i p =
        _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(positive + x)), zero);
    const __m128i n =
        _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(negative + x)), zero);
    const __m128i difference = _mm_sub_epi16(p, n);
    const __m128i is_one = _mm_cmpgt_epi16(difference, psi);
    const __m128i known = _mm_or_si128(is_one, _mm_cmplt_epi16(difference, minus_psi));
    __m128i g = _mm_loadu_si128(reinterpret_cast<const __m128i*>(gray + x));
    __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(valid + x));
    // Algorithm 1.
    const __m128i new_bit = _mm_and_si128(is_one, bit);
    const __m128i same = _mm_cmpeq_epi16(_mm_and_si128(g, bit), new_bit);
    const __m128i old_known = _mm_cmpeq_epi16(_mm_and_si128(v, bit), bit);
    const __m128i correct =
        _mm_and_si128(_mm_andnot_si128(same, _mm_and_si128(old_known, known)), correction);
    g = _mm_or_si128(_mm_andnot_si128(bit, g), new_bit);
    g = _mm_or_si128(_mm_andnot_si128(_mm_and_si128(lower, correct), g),
                     _mm_and_si128(forced, correct));
    v = _mm_or_si128(_mm_andnot_si128(bit, v), _mm_and_si128(known, bit));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(gray + x), g);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(valid + x), v);
    // Gray -> binary, invalid pixels to the NaN plane.
    __m128i b = _mm_xor_si128(g, _mm_srli_epi16(g, 1));
    b = _mm_xor_si128(b, _mm_srli_epi16(b, 2));
    b = _mm_xor_si128(b, _mm_srli_epi16(b, 4));
    b = _mm_xor_si128(b, _mm_srli_epi16(b, 8));
    const __m128i ok = _mm_cmpeq_epi16(v, full);
    const __m128i index = _mm_or_si128(_mm_and_si128(ok, b), _mm_andnot_si128(ok, invalid));
    const int i0 = _mm_extract_epi16(index, 0), i1 = _mm_extract_epi16(index, 1);
    const int i2 = _mm_extract_epi16(index, 2), i3 = _mm_extract_epi16(index, 3);
    const int i4 = _mm_extract_epi16(index, 4), i5 = _mm_extract_epi16(index, 5);
    const int i6 = _mm_extract_epi16(index, 6), i7 = _mm_extract_epi16(index, 7);
    const int lanes[2][4] = {{i0, i1, i2, i3}, {i4, i5, i6, i7}};
    for (int half = 0; half < 2; ++half) {
      __m128 pa = _mm_loadu_ps(planes + 4 * lanes[half][0]);
      __m128 pb = _mm_loadu_ps(planes + 4 * lanes[half][1]);
      __m128 pc = _mm_loadu_ps(planes + 4 * lanes[half][2]);
      __m128 pd = _mm_loadu_ps(planes + 4 * lanes[half][3]);
      _MM_TRANSPOSE4_PS(pa, pb, pc, pd);  // pa = a, pb = b, pc = c of the 4 pixels
      const int o = x + 4 * half;
      const __m128 ry = kRowRay ? _mm_set1_ps(ray_y[0]) : _mm_loadu_ps(ray_y + o);
      const __m128 den =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(pa, _mm_loadu_ps(ray_x + o)), _mm_mul_ps(pb, ry)), pc);
      const __m128 z = _mm_div_ps(one, den);
      const __m128 in_range = _mm_and_ps(_mm_cmpgt_ps(z, zmin), _mm_cmplt_ps(z, zmax));
      _mm_storeu_ps(depth + o, _mm_or_ps(_mm_and_ps(in_range, z), _mm_andnot_ps(in_range, nan)));
    }
  }
  update_row<true, kRowRay>(positive, negative, gray, valid, depth, ray_x, ray_y, a, x);
}

// AVX2 (chosen at run time): the 16-bit steps on 16 pixels at once, then the depth of each
// half through load_planes8 (plane_lookup_avx2.hpp).
// kWithDepth = false: the bits only (while the window is incomplete), with kCodes the binary
// codes as well (update_row).
template <bool kWithDepth, bool kRowRay, bool kCodes = false>
__attribute__((target("avx2"))) void update_row_avx2(
    const std::uint8_t* __restrict positive, const std::uint8_t* __restrict negative,
    std::uint16_t* __restrict gray, std::uint16_t* __restrict valid, float* __restrict depth,
    const float* __restrict ray_x, const float* __restrict ray_y, const PairUpdateArgs& a) {
  const auto bit_mask = static_cast<std::uint16_t>(1u << a.bit_position);
  const __m256i psi = _mm256_set1_epi16(static_cast<short>(a.threshold_psi));
  const __m256i minus_psi = _mm256_set1_epi16(static_cast<short>(-a.threshold_psi));
  const __m256i bit = _mm256_set1_epi16(static_cast<short>(bit_mask));
  const __m256i lower = _mm256_set1_epi16(static_cast<short>(bit_mask - 1u));
  const __m256i forced = _mm256_set1_epi16(static_cast<short>(bit_mask >> 1));
  const __m256i correction = _mm256_set1_epi16(a.code_correction ? static_cast<short>(-1) : 0);
  const __m256i full = _mm256_set1_epi16(static_cast<short>(a.full_mask));
  const __m256i invalid = _mm256_set1_epi16(static_cast<short>(a.invalid_index));
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 zmin = _mm256_set1_ps(a.min_depth_m);
  const __m256 zmax = _mm256_set1_ps(a.max_depth_m);
  const __m256 nan = _mm256_set1_ps(std::numeric_limits<float>::quiet_NaN());
  const float* planes = a.planes;
  std::int16_t* __restrict codes = kCodes ? a.codes + (gray - a.gray) : nullptr;
  const __m256i code_count = _mm256_set1_epi16(static_cast<short>(a.code_count));
  const __m256i minus_one = _mm256_set1_epi16(-1);
  // Depth of the 8 pixels from x on, with plane indices `index` (8 x 16 bit).
  const auto depth8 = [&](__m128i index, int x) __attribute__((target("avx2"))) {
    const auto lo = static_cast<std::uint64_t>(_mm_cvtsi128_si64(index));
    const auto hi = static_cast<std::uint64_t>(_mm_extract_epi64(index, 1));
    const float* rows[8];
    for (int k = 0; k < 4; ++k) {
      rows[k] = planes + 4 * ((lo >> (16 * k)) & 0xffffu);
      rows[k + 4] = planes + 4 * ((hi >> (16 * k)) & 0xffffu);
    }
    const auto [pa, pb, pc] = load_planes8(rows);
    const __m256 ry = kRowRay ? _mm256_set1_ps(ray_y[0]) : _mm256_loadu_ps(ray_y + x);
    const __m256 den = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(pa, _mm256_loadu_ps(ray_x + x)), _mm256_mul_ps(pb, ry)), pc);
    const __m256 z = _mm256_div_ps(one, den);
    const __m256 in_range =
        _mm256_and_ps(_mm256_cmp_ps(z, zmin, _CMP_GT_OQ), _mm256_cmp_ps(z, zmax, _CMP_LT_OQ));
    _mm256_storeu_ps(depth + x, _mm256_blendv_ps(nan, z, in_range));
  };
  int x = 0;
  for (; x + 16 <= a.width; x += 16) {
    // Eq. 2.
    const __m256i p =
        _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(positive + x)));
    const __m256i n =
        _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(negative + x)));
    const __m256i difference = _mm256_sub_epi16(p, n);
    const __m256i is_one = _mm256_cmpgt_epi16(difference, psi);
    const __m256i known = _mm256_or_si256(is_one, _mm256_cmpgt_epi16(minus_psi, difference));
    __m256i g = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(gray + x));
    __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(valid + x));
    // Algorithm 1.
    const __m256i new_bit = _mm256_and_si256(is_one, bit);
    const __m256i same = _mm256_cmpeq_epi16(_mm256_and_si256(g, bit), new_bit);
    const __m256i old_known = _mm256_cmpeq_epi16(_mm256_and_si256(v, bit), bit);
    const __m256i correct =
        _mm256_and_si256(_mm256_andnot_si256(same, _mm256_and_si256(old_known, known)), correction);
    g = _mm256_or_si256(_mm256_andnot_si256(bit, g), new_bit);
    g = _mm256_or_si256(_mm256_andnot_si256(_mm256_and_si256(lower, correct), g),
                        _mm256_and_si256(forced, correct));
    v = _mm256_or_si256(_mm256_andnot_si256(bit, v), _mm256_and_si256(known, bit));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(gray + x), g);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(valid + x), v);
    // Gray -> binary, invalid pixels to the NaN plane.
    __m256i b = _mm256_xor_si256(g, _mm256_srli_epi16(g, 1));
    b = _mm256_xor_si256(b, _mm256_srli_epi16(b, 2));
    b = _mm256_xor_si256(b, _mm256_srli_epi16(b, 4));
    b = _mm256_xor_si256(b, _mm256_srli_epi16(b, 8));
    const __m256i ok = _mm256_cmpeq_epi16(v, full);
    if constexpr (kCodes) {  // b < 2^15 (at most 15 bits): a signed comparison
      const __m256i code_ok = _mm256_and_si256(ok, _mm256_cmpgt_epi16(code_count, b));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(codes + x),
                          _mm256_blendv_epi8(minus_one, b, code_ok));
    }
    const __m256i index =
        _mm256_or_si256(_mm256_and_si256(ok, b), _mm256_andnot_si256(ok, invalid));
    if constexpr (kWithDepth) {
      depth8(_mm256_castsi256_si128(index), x);
      depth8(_mm256_extracti128_si256(index, 1), x + 8);
    }
  }
  // Clean upper halves before the tail and the (SSE) caller: GCC 12 did not always insert the
  // vzeroupper (subcode.cpp, triangulate_subcode_avx2).
  _mm256_zeroupper();
  update_row<kWithDepth, kRowRay, kCodes>(positive, negative, gray, valid, depth, ray_x, ray_y, a,
                                          x);
}
#endif

}  // namespace

KernelIsa best_kernel_isa() {
#if defined(AVS_DECODE_X86)
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  return has_avx2 ? KernelIsa::kAvx2 : KernelIsa::kSse2;
#else
  return KernelIsa::kScalar;
#endif
}

const char* kernel_isa_name(KernelIsa isa) {
  switch (isa) {
    case KernelIsa::kScalar:
      return "scalar";
    case KernelIsa::kSse2:
      return "sse2";
    case KernelIsa::kAvx2:
      return "avx2";
  }
  return "?";
}

void update_pair(const PairUpdateArgs& a) {
  update_pair(a, best_kernel_isa());
}

void update_pair(const PairUpdateArgs& a, KernelIsa isa) {
#if !defined(AVS_DECODE_X86)
  isa = KernelIsa::kScalar;
#endif
  const bool row_rays = a.column_ray_x != nullptr && a.row_ray_y != nullptr;
  for (int y = 0; y < a.height; ++y) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * a.width;
    const auto* positive = a.positive + y * a.positive_stride;
    const auto* negative = a.negative + y * a.negative_stride;
    if (a.depth_m == nullptr) {
      const bool codes = a.codes != nullptr;
#if defined(AVS_DECODE_X86)
      if (isa == KernelIsa::kAvx2) {
        (codes ? update_row_avx2<false, false, true>
               : update_row_avx2<false, false, false>)(positive, negative, a.gray + row,
                                                       a.valid + row, nullptr, nullptr, nullptr, a);
        continue;
      }
#endif
      (codes ? update_row<false, false, true>
             : update_row<false, false, false>)(positive, negative, a.gray + row, a.valid + row,
                                                nullptr, nullptr, nullptr, a, 0);
      continue;
    }
    float* depth = a.depth_m + row;
    // Separable rays: one row of x for every row, one y per row (2 floats per pixel less).
    const float* ray_x = row_rays ? a.column_ray_x : a.ray_x + row;
    const float* ray_y = row_rays ? a.row_ray_y + y : a.ray_y + row;
    switch (isa) {
#if defined(AVS_DECODE_X86)
      case KernelIsa::kAvx2:
        (row_rays ? update_row_avx2<true, true>
                  : update_row_avx2<true, false>)(positive, negative, a.gray + row, a.valid + row,
                                                  depth, ray_x, ray_y, a);
        break;
      case KernelIsa::kSse2:
        (row_rays ? update_row_sse2<true> : update_row_sse2<false>)(positive, negative,
                                                                    a.gray + row, a.valid + row,
                                                                    depth, ray_x, ray_y, a);
        break;
#endif
      default:
        (row_rays ? update_row<true, true> : update_row<true, false>)(positive, negative,
                                                                      a.gray + row, a.valid + row,
                                                                      depth, ray_x, ray_y, a, 0);
    }
  }
}

}  // namespace avs::decode::detail
