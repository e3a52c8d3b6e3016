#include "subcode.hpp"

#include "plane_lookup_avx2.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace avs::decode::detail {

SubcodeRefiner::SubcodeRefiner(SubcodeParams params) : params_(params) {
  if (params_.width <= 0 || params_.height <= 0 || params_.half_window < 1 ||
      params_.half_window > 16 || params_.max_jump < 0) {
    throw std::invalid_argument(
        "sub-code refinement: half window " + std::to_string(params_.half_window) +
        " outside 1..16 or max jump " + std::to_string(params_.max_jump) + " negative");
  }
  const auto w = static_cast<std::size_t>(params_.width);
  n_.assign(w, 0);
  sy_.assign(w, 0);
  syy_.assign(w, 0);
  sc_.assign(w, 0);
  scy_.assign(w, 0);
  jumps_.assign(w, 0);
  previous_.assign(w, 0);
  previous_y_.assign(w, 0);
  jump_.assign(w * static_cast<std::size_t>(params_.height), 0);
}

namespace {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__)
// Plain loops over arrays: the compiler vectorises them; with AVX2 when the CPU has it (the
// default build has no -march flag). Not under TSan: the clones' ifunc resolver is instrumented
// and runs at relocation time, before TSan is initialised (`avs` crashed before main).
#define AVS_SUBCODE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define AVS_SUBCODE_CLONES
#endif

struct Sums {
  std::int32_t* __restrict n;
  std::int32_t* __restrict sy;
  std::int32_t* __restrict syy;
  std::int32_t* __restrict sc;
  std::int32_t* __restrict scy;
  std::int32_t* __restrict jumps;
};

// One step of the window for output row y0, in one pass over the columns (the sums stay in
// registers): row y_in = y0 + h enters (kAdd; its discontinuity flags against the previous valid
// code of each column, at most reach = 2h rows up, are computed and stored), row
// y_out = y0 - h - 1 leaves (kRemove), then (kOutput) the line fit about y0 from the window sums
// (exact integers, d = y - y0): its value at d = 0, clamped to the pixel's code +- 1, else the code
// itself. Branch-free (bitwise &, blends by multiplication) so that the loop vectorises; integer
// sums are exact, so the order of entering and leaving does not change a result.
template <bool kAdd, bool kRemove, bool kOutput = true>
AVS_SUBCODE_CLONES void window_step(const std::int16_t* __restrict entering,
                                    std::uint8_t* __restrict entering_jump,
                                    const std::int16_t* __restrict leaving,
                                    const std::uint8_t* __restrict leaving_jump,
                                    const std::int16_t* __restrict row, float* __restrict out,
                                    std::int16_t* __restrict previous,
                                    std::int32_t* __restrict previous_y, Sums s, int width,
                                    int y_in, int y_out, int y0, int reach, int max_jump) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::int32_t yy_in = y_in * y_in;
  const std::int32_t yy_out = y_out * y_out;
  const std::int32_t two_y0 = 2 * y0;
  const std::int32_t y0y0 = y0 * y0;
  for (int x = 0; x < width; ++x) {
    std::int32_t n = s.n[x], sy = s.sy[x], syy = s.syy[x], sc = s.sc[x], scy = s.scy[x],
                 jumps = s.jumps[x];
    if constexpr (kAdd) {
      const std::int32_t c = entering[x];
      const std::int32_t valid = -static_cast<std::int32_t>(c >= 0);       // all ones when valid
      const std::int32_t gap = std::min(y_in - previous_y[x], reach + 1);  // no overflow below
      const std::int32_t difference = c - previous[x];
      const std::int32_t magnitude = std::abs(difference);
      const std::int32_t j = valid & static_cast<std::int32_t>(gap <= reach) &
                             static_cast<std::int32_t>(magnitude > max_jump * gap);
      entering_jump[x] = static_cast<std::uint8_t>(j);
      previous[x] = static_cast<std::int16_t>(previous[x] + (valid & difference));
      previous_y[x] += valid & (y_in - previous_y[x]);
      const std::int32_t vc = valid & c;
      n -= valid;
      sy += valid & y_in;
      syy += valid & yy_in;
      sc += vc;
      scy += vc * y_in;
      jumps += j;
    }
    if constexpr (kRemove) {
      const std::int32_t c = leaving[x];
      const std::int32_t valid = -static_cast<std::int32_t>(c >= 0);
      const std::int32_t vc = valid & c;
      n += valid;
      sy -= valid & y_out;
      syy -= valid & yy_out;
      sc -= vc;
      scy -= vc * y_out;
      jumps -= leaving_jump[x];
    }
    s.n[x] = n;
    s.sy[x] = sy;
    s.syy[x] = syy;
    s.sc[x] = sc;
    s.scy[x] = scy;
    s.jumps[x] = jumps;
    if constexpr (!kOutput) continue;
    const std::int32_t c0 = row[x];
    const std::int32_t sd = sy - n * y0;
    const std::int32_t sdd = syy - two_y0 * sy + n * y0y0;
    const std::int32_t scd = scy - y0 * sc;
    const std::int32_t det = n * sdd - sd * sd;
    const std::int32_t fit = static_cast<std::int32_t>(jumps == 0) &
                             static_cast<std::int32_t>(n >= 3) & static_cast<std::int32_t>(det > 0);
    const auto c = static_cast<float>(c0);
    const std::int32_t divisor = fit * det + (1 - fit);
    const float intercept = static_cast<float>(sc * sdd - scd * sd) / static_cast<float>(divisor);
    const float clamped = std::min(std::max(intercept, c - 1.0f), c + 1.0f);
    const float u = fit != 0 ? clamped : c;
    out[x] = c0 >= 0 ? u : nan;
  }
}

}  // namespace

AVS_SUBCODE_CLONES void codes_from_gray(const std::uint16_t* __restrict gray,
                                        const std::uint16_t* __restrict valid, std::uint16_t full,
                                        int code_count, std::int16_t* __restrict codes,
                                        int pixels) {
  for (int i = 0; i < pixels; ++i) {
    auto b = static_cast<std::uint16_t>(gray[i] ^ (gray[i] >> 1));  // Eq. 3, Gray -> binary
    b = static_cast<std::uint16_t>(b ^ (b >> 2));
    b = static_cast<std::uint16_t>(b ^ (b >> 4));
    b = static_cast<std::uint16_t>(b ^ (b >> 8));
    codes[i] = static_cast<std::int16_t>(valid[i] == full && b < code_count ? b : -1);
  }
}

namespace {

// Depth through the sub-code plane of each fractional code, one pixel at a time (the
// reference the AVX2 loop below must equal bit for bit: the same operations in the same order).
void triangulate_subcode_plain(const float* __restrict refined, const SubcodePlanes& planes,
                               const float* __restrict ray_x, const float* __restrict ray_y,
                               float min_depth_m, float max_depth_m, float* __restrict depth,
                               int begin, int pixels) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto steps = static_cast<float>(planes.steps);
  const auto count = static_cast<float>(planes.count);
  const float* __restrict table = planes.planes;
  for (int i = begin; i < pixels; ++i) {
    const float position = (refined[i] + 0.5f) * steps + 0.5f;
    const bool ok = (position >= 0.0f) & (position < count);  // false for NaN
    const float* pl = table + 4 * (ok ? static_cast<int>(position) : 0);
    const float z = 1.0f / (pl[0] * ray_x[i] + pl[1] * ray_y[i] + pl[2]);
    depth[i] = (ok & (z > min_depth_m) & (z < max_depth_m)) ? z : nan;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
// 8 pixels at once: the plane rows by load_planes8 (a compiler-made gather was scalar), the
// division exact (vdivps, as divss), no fused multiply-add: the same depth as the plain loop.
__attribute__((target("avx2"))) void triangulate_subcode_avx2(const float* __restrict refined,
                                                              const SubcodePlanes& planes,
                                                              const float* __restrict ray_x,
                                                              const float* __restrict ray_y,
                                                              float min_depth_m, float max_depth_m,
                                                              float* __restrict depth, int pixels) {
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 steps = _mm256_set1_ps(static_cast<float>(planes.steps));
  const __m256 count = _mm256_set1_ps(static_cast<float>(planes.count));
  const __m256 zero = _mm256_setzero_ps();
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 zmin = _mm256_set1_ps(min_depth_m);
  const __m256 zmax = _mm256_set1_ps(max_depth_m);
  const __m256 nan = _mm256_set1_ps(std::numeric_limits<float>::quiet_NaN());
  const float* table = planes.planes;
  int i = 0;
  for (; i + 8 <= pixels; i += 8) {
    const __m256 position = _mm256_add_ps(
        _mm256_mul_ps(_mm256_add_ps(_mm256_loadu_ps(refined + i), half), steps), half);
    const __m256 ok = _mm256_and_ps(_mm256_cmp_ps(position, zero, _CMP_GE_OQ),
                                    _mm256_cmp_ps(position, count, _CMP_LT_OQ));
    const __m256i index = _mm256_and_si256(_mm256_cvttps_epi32(position), _mm256_castps_si256(ok));
    alignas(32) std::int32_t idx[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(idx), index);
    const float* rows[8];
    for (int k = 0; k < 8; ++k) rows[k] = table + 4 * idx[k];
    const auto [pa, pb, pc] = load_planes8(rows);
    const __m256 den = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(pa, _mm256_loadu_ps(ray_x + i)),
                                                   _mm256_mul_ps(pb, _mm256_loadu_ps(ray_y + i))),
                                     pc);
    const __m256 z = _mm256_div_ps(one, den);
    const __m256 keep = _mm256_and_ps(
        ok, _mm256_and_ps(_mm256_cmp_ps(z, zmin, _CMP_GT_OQ), _mm256_cmp_ps(z, zmax, _CMP_LT_OQ)));
    _mm256_storeu_ps(depth + i, _mm256_blendv_ps(nan, z, keep));
  }
  triangulate_subcode_plain(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth, i,
                            pixels);
}
#endif

}  // namespace

void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels) {
  static const KernelIsa isa = best_kernel_isa();
  triangulate_subcode(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth, pixels, isa);
}

void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels, KernelIsa isa) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (isa == KernelIsa::kAvx2) {
    triangulate_subcode_avx2(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth,
                             pixels);
    return;
  }
#endif
  triangulate_subcode_plain(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth, 0,
                            pixels);
}

void SubcodeRefiner::refine(const std::int16_t* codes, float* refined, RowSink* sink) {
  const int w = params_.width;
  const int h = params_.height;
  const int half = params_.half_window;
  std::fill(previous_.begin(), previous_.end(), 0);
  std::fill(previous_y_.begin(), previous_y_.end(), std::numeric_limits<std::int32_t>::min() / 2);
  std::fill(n_.begin(), n_.end(), 0);
  std::fill(sy_.begin(), sy_.end(), 0);
  std::fill(syy_.begin(), syy_.end(), 0);
  std::fill(sc_.begin(), sc_.end(), 0);
  std::fill(scy_.begin(), scy_.end(), 0);
  std::fill(jumps_.begin(), jumps_.end(), 0);
  const Sums sums{n_.data(), sy_.data(), syy_.data(), sc_.data(), scy_.data(), jumps_.data()};
  const auto row_of = [&](int y) { return codes + static_cast<std::ptrdiff_t>(y) * w; };
  const auto jump_of = [&](int y) { return jump_.data() + static_cast<std::ptrdiff_t>(y) * w; };
  const int max_jump = params_.max_jump;
  // The window's first h rows enter without an output row.
  for (int y = 0; y < std::min(half, h); ++y) {
    window_step<true, false, false>(row_of(y), jump_of(y), nullptr, nullptr, nullptr, nullptr,
                                    previous_.data(), previous_y_.data(), sums, w, y, 0, 0,
                                    2 * half, max_jump);
  }
  for (int y0 = 0; y0 < h; ++y0) {
    const bool enters = y0 + half < h;
    const bool leaves = y0 - half - 1 >= 0;
    const int y_in = enters ? y0 + half : y0;
    const int y_out = leaves ? y0 - half - 1 : y0;
    auto* step = enters ? (leaves ? &window_step<true, true> : &window_step<true, false>)
                        : (leaves ? &window_step<false, true> : &window_step<false, false>);
    step(row_of(y_in), jump_of(y_in), row_of(y_out), jump_of(y_out), row_of(y0),
         refined + static_cast<std::ptrdiff_t>(y0) * w, previous_.data(), previous_y_.data(), sums,
         w, y_in, y_out, y0, 2 * half, max_jump);
    if (sink != nullptr) sink->row_done(y0, refined + static_cast<std::ptrdiff_t>(y0) * w);
  }
}

}  // namespace avs::decode::detail
