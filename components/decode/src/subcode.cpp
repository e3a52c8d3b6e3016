#include "subcode.hpp"

#include "plane_lookup_avx2.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace avs::decode::detail {

SubcodeRefiner::SubcodeRefiner(SubcodeParams params, KernelIsa isa) : params_(params), isa_(isa) {
  if (params_.width <= 0 || params_.height <= 0 || params_.half_window < 1 ||
      params_.half_window > 16 || params_.max_jump < 0) {
    throw std::invalid_argument(
        "sub-code refinement: half window " + std::to_string(params_.half_window) +
        " outside 1..16 or max jump " + std::to_string(params_.max_jump) + " negative");
  }
  // A code changes by at most 32767 (codes are int16), so a larger max_jump flags nothing more
  // than 32767 does: clamped, max_jump x gap stays within int32 in the plain step and within the
  // 16-bit factors of the AVX2 steps' products (vpmaddwd, vpmullw).
  params_.max_jump = std::min(params_.max_jump, 32767);
  const auto w = static_cast<std::size_t>(params_.width);
  // The 16-bit sums are exact (wrapping arithmetic, exact at every output) when the largest
  // values fit: sc <= (2h + 1) c and the mean's clamp bound (2h + 1)(c + 1), |scd| <= h (h + 1) c
  // for c = the largest code; the rows (y, and the gap before a discontinuity times max_jump)
  // fit as well.
  const int h = params_.half_window;
  const long largest_code = static_cast<long>(params_.code_count) - 1;
  narrow_ = params_.code_count > 0 && static_cast<long>(2 * h + 1) * params_.code_count < 32768 &&
            static_cast<long>(h) * (h + 1) * largest_code < 32768 &&
            static_cast<long>(2 * h + 2) * params_.max_jump < 32768 && params_.height < 32768;
  if (narrow_) {
    for (auto* v : {&n16_, &sc16_, &jumps16_, &previous_y16_}) {
      v->assign(w, 0);
    }
  }
  n_.assign(w, 0);
  sd_.assign(w, 0);
  sdd_.assign(w, 0);
  sc_.assign(w, 0);
  scd_.assign(w, 0);
  jumps_.assign(w, 0);
  previous_.assign(w, 0);
  previous_y_.assign(w, 0);
  jump_.assign(w * static_cast<std::size_t>(2 * params_.half_window + 2), 0);
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

// Per column running sums of the window (SubcodeRefiner's 32-bit arrays).
struct Sums {
  std::int32_t* __restrict n;
  std::int32_t* __restrict sd;
  std::int32_t* __restrict sdd;
  std::int32_t* __restrict sc;
  std::int32_t* __restrict scd;
  std::int32_t* __restrict jumps;
};

// The sums the 16-column AVX2 step keeps per column (16 bits): count, code, discontinuities.
struct NarrowSums {
  std::int16_t* __restrict n;
  std::int16_t* __restrict sc;
  std::int16_t* __restrict jumps;
};

struct StepArgs {
  const std::int16_t* entering;  ///< row y_in
  std::uint8_t* entering_jump;
  const std::int16_t* leaving;  ///< row y0 - h - 1
  const std::uint8_t* leaving_jump;
  const std::int16_t* row;  ///< row y0
  float* out;               ///< refined row y0
  std::int16_t* previous;
  std::int32_t* previous_y;
  Sums s;
  int width, y_in, d_in, d_out, reach, max_jump;
  /// The 16-bit sums and previous rows when they are exact (SubcodeRefiner), else null.
  const NarrowSums* narrow;
  std::int16_t* previous_y16;
  /// The window's rows about y0 (kOutput): the first (clipped to the image) and how many, and
  /// the first one's offset d = y - y0.
  const std::int16_t* window_first = nullptr;
  int window_rows = 0;
  int window_first_d = 0;
};

// One step of the window for output row y0, in one pass over the columns (the sums stay in
// registers). The sums are about the output row (d = y - y0), so that moving the window needs
// additions only: (kOutput) the origin moves from y0 - 1 to y0, every member's d dropping by one
// (sd -= n, sdd -= 2 sd - n, scd -= sc); row y_out = y0 - h - 1 leaves (kRemove, d_out = -h - 1);
// row y_in enters (kAdd, d_in = h, or its own offset while the first rows fill the window) and its
// discontinuity flags against the previous valid code of each column, at most reach = 2h rows up,
// are computed and stored; then (kOutput) the line fit about y0 from the window sums: its value
// at d = 0, clamped to the pixel's code +- 1, else the code itself. Branch-free (bitwise &,
// blends by multiplication); the sums are exact integers, so the order of the steps does not
// change a result (tests/decode/subcode_test.cpp compares with the fit written pixel by pixel).
// Columns begin .. width - 1, one at a time: the reference of the AVX2 steps below, and their
// remaining columns.
template <bool kAdd, bool kRemove, bool kOutput>
void window_step_plain(const StepArgs& a, int begin) {
  const std::int16_t* __restrict entering = a.entering;
  std::uint8_t* __restrict entering_jump = a.entering_jump;
  const std::int16_t* __restrict leaving = a.leaving;
  const std::uint8_t* __restrict leaving_jump = a.leaving_jump;
  const std::int16_t* __restrict row = a.row;
  float* __restrict out = a.out;
  std::int16_t* __restrict previous = a.previous;
  std::int32_t* __restrict previous_y = a.previous_y;
  const Sums s = a.s;
  const int y_in = a.y_in, d_in = a.d_in, d_out = a.d_out, reach = a.reach;
  const int max_jump = a.max_jump;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::int32_t dd_in = d_in * d_in;
  const std::int32_t dd_out = d_out * d_out;
  for (int x = begin; x < a.width; ++x) {
    std::int32_t n = s.n[x], sd = s.sd[x], sdd = s.sdd[x], sc = s.sc[x], scd = s.scd[x],
                 jumps = s.jumps[x];
    if constexpr (kOutput) {
      sdd += n - 2 * sd;
      sd -= n;
      scd -= sc;
    }
    if constexpr (kRemove) {
      const std::int32_t c = leaving[x];
      const std::int32_t valid = -static_cast<std::int32_t>(c >= 0);
      const std::int32_t vc = valid & c;
      n += valid;
      sd -= valid & d_out;
      sdd -= valid & dd_out;
      sc -= vc;
      scd -= vc * d_out;
      jumps -= leaving_jump[x];
    }
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
      sd += valid & d_in;
      sdd += valid & dd_in;
      sc += vc;
      scd += vc * d_in;
      jumps += j;
    }
    s.n[x] = n;
    s.sd[x] = sd;
    s.sdd[x] = sdd;
    s.sc[x] = sc;
    s.scd[x] = scd;
    s.jumps[x] = jumps;
    if constexpr (!kOutput) continue;
    const std::int32_t c0 = row[x];
    const std::int32_t det = n * sdd - sd * sd;
    const std::int32_t fit = static_cast<std::int32_t>(jumps == 0) &
                             static_cast<std::int32_t>(n >= 3) & static_cast<std::int32_t>(det > 0);
    const auto c = static_cast<float>(c0);
    // A symmetric window (sd = 0) gives the fit's value at d = 0 as the mean sc / n; written so,
    // the AVX2 step can take it by a multiplication (see there).
    const std::int32_t symmetric = static_cast<std::int32_t>(sd == 0);
    const std::int32_t numerator = symmetric * sc + (1 - symmetric) * (sc * sdd - scd * sd);
    const std::int32_t divisor = fit * (symmetric * n + (1 - symmetric) * det) + (1 - fit);
    const float intercept = static_cast<float>(numerator) / static_cast<float>(divisor);
    const float clamped = std::min(std::max(intercept, c - 1.0f), c + 1.0f);
    const float u = fit != 0 ? clamped : c;
    out[x] = c0 >= 0 ? u : nan;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define AVS_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

// 8 int16 as 8 int32.
AVS_AVX2_INLINE __m256i load16(const std::int16_t* p) {
  return _mm256_cvtepi16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}
AVS_AVX2_INLINE __m256i load32(const std::int32_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
AVS_AVX2_INLINE void store32(std::int32_t* p, __m256i v) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v);
}
// 8 int32 lanes (each within int16) as 8 int16.
AVS_AVX2_INLINE __m128i pack16(__m256i v) {
  return _mm_packs_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
}

// The window's sums of 8 columns, and the steps of the plain loop on them one for one (exact
// integers, then the one float division), so that both give bit-identical codes
// (tests/decode/subcode_test.cpp). Products of small factors (a code and a row offset, max_jump
// and a gap of at most 2h + 1 rows) by vpmaddwd.
struct Window8 {
  __m256i n, sd, sdd, sc, scd, jumps;
};

struct WindowConstants8 {
  __m256i zero, one, minus_one, two;
  // Row offsets as int16 in the low half of each lane (upper half zero, for vpmaddwd with a
  // code) and as int32.
  __m256i d_in16, dd_in, d_out, d_out16, dd_out;
  __m256i beyond, max_jump16;
  __m256i full;  // rows of a complete window, 2h + 1
  __m256d inverse_full;
  __m256 one_f, nan;

  AVS_AVX2_INLINE WindowConstants8(int d_in, int d_out, int reach, int max_jump)
      : zero(_mm256_setzero_si256()),
        one(_mm256_set1_epi32(1)),
        minus_one(_mm256_set1_epi32(-1)),
        two(_mm256_set1_epi32(2)),
        d_in16(_mm256_set1_epi32(d_in & 0xffff)),
        dd_in(_mm256_set1_epi32(d_in * d_in)),
        d_out(_mm256_set1_epi32(d_out)),
        d_out16(_mm256_set1_epi32(d_out & 0xffff)),
        dd_out(_mm256_set1_epi32(d_out * d_out)),
        beyond(_mm256_set1_epi32(reach + 1)),
        max_jump16(_mm256_set1_epi32(max_jump)),
        full(_mm256_set1_epi32(reach + 1)),
        inverse_full(_mm256_set1_pd(1.0 / (reach + 1))),
        one_f(_mm256_set1_ps(1.0f)),
        nan(_mm256_set1_ps(std::numeric_limits<float>::quiet_NaN())) {}
};

// The origin moves from y0 - 1 to y0.
AVS_AVX2_INLINE void shift8(Window8& w) {
  w.sdd = _mm256_sub_epi32(_mm256_add_epi32(w.sdd, w.n), _mm256_slli_epi32(w.sd, 1));
  w.sd = _mm256_sub_epi32(w.sd, w.n);
  w.scd = _mm256_sub_epi32(w.scd, w.sc);
}

// Codes c (-1 invalid) of row y0 - h - 1 leave, with their discontinuity flags (0 or 1).
AVS_AVX2_INLINE void remove8(Window8& w, __m256i c, __m256i jump, const WindowConstants8& k) {
  const __m256i valid = _mm256_cmpgt_epi32(c, k.minus_one);
  const __m256i vc = _mm256_and_si256(valid, c);  // 0 .. 32767, upper half zero
  w.n = _mm256_add_epi32(w.n, valid);
  w.sd = _mm256_sub_epi32(w.sd, _mm256_and_si256(valid, k.d_out));
  w.sdd = _mm256_sub_epi32(w.sdd, _mm256_and_si256(valid, k.dd_out));
  w.sc = _mm256_sub_epi32(w.sc, vc);
  w.scd = _mm256_sub_epi32(w.scd, _mm256_madd_epi16(vc, k.d_out16));
  w.jumps = _mm256_sub_epi32(w.jumps, jump);
}

// Codes c of row y_in enter; returns their discontinuity flags (0 or 1) against the previous
// valid code of each column (and its row), which it updates.
AVS_AVX2_INLINE __m256i add8(Window8& w, __m256i c, __m256i y_in, __m256i d_in, __m256i dd_in,
                             __m256i& previous, __m256i& previous_y, const WindowConstants8& k) {
  const __m256i valid = _mm256_cmpgt_epi32(c, k.minus_one);
  // 1 .. 2h + 1 (the previous valid row is above), so max_jump * gap by vpmaddwd.
  const __m256i gap = _mm256_min_epi32(_mm256_sub_epi32(y_in, previous_y), k.beyond);
  const __m256i difference = _mm256_sub_epi32(c, previous);
  const __m256i magnitude = _mm256_abs_epi32(difference);
  const __m256i j = _mm256_and_si256(
      _mm256_and_si256(valid, _mm256_cmpgt_epi32(k.beyond, gap)),
      _mm256_and_si256(_mm256_cmpgt_epi32(magnitude, _mm256_madd_epi16(k.max_jump16, gap)), k.one));
  previous = _mm256_add_epi32(previous, _mm256_and_si256(valid, difference));
  previous_y =
      _mm256_add_epi32(previous_y, _mm256_and_si256(valid, _mm256_sub_epi32(y_in, previous_y)));
  const __m256i vc = _mm256_and_si256(valid, c);
  w.n = _mm256_sub_epi32(w.n, valid);
  w.sd = _mm256_add_epi32(w.sd, _mm256_and_si256(valid, d_in));
  w.sdd = _mm256_add_epi32(w.sdd, _mm256_and_si256(valid, dd_in));
  w.sc = _mm256_add_epi32(w.sc, vc);
  w.scd = _mm256_add_epi32(w.scd, _mm256_madd_epi16(vc, d_in));
  w.jumps = _mm256_add_epi32(w.jumps, j);
  return j;
}

// The mean sc / n of complete windows (n = 2h + 1) as sc * (1 / n) in double, rounded once to
// float. That is the float division sc / n bit for bit: sc and n are exact, n is odd, so sc / n
// is never within about 2^-30 (relative) of a float rounding midpoint, and the double product is
// within 2^-52 of it (an exhaustive check in tests/decode/subcode_test.cpp). No division.
AVS_AVX2_INLINE __m256 mean8(__m256i sc, const WindowConstants8& k) {
  const __m128 low = _mm256_cvtpd_ps(
      _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(sc)), k.inverse_full));
  const __m128 high = _mm256_cvtpd_ps(
      _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(sc, 1)), k.inverse_full));
  return _mm256_insertf128_ps(_mm256_castps128_ps256(low), high, 1);
}

// The refined codes from the fit's value at d = 0 where `fit` (all ones), codes c0 (-1 invalid):
// NaN, the code, or the value clamped to the code +- 1.
AVS_AVX2_INLINE __m256 refined8(__m256 intercept, __m256i fit, __m256i c0,
                                const WindowConstants8& k) {
  const __m256 c = _mm256_cvtepi32_ps(c0);
  const __m256 clamped =
      _mm256_min_ps(_mm256_max_ps(intercept, _mm256_sub_ps(c, k.one_f)), _mm256_add_ps(c, k.one_f));
  const __m256 u = _mm256_blendv_ps(c, clamped, _mm256_castsi256_ps(fit));
  return _mm256_blendv_ps(k.nan, u, _mm256_castsi256_ps(_mm256_cmpgt_epi32(c0, k.minus_one)));
}

// The refined codes of row y0 (codes c0). A block whose fitted windows are all complete takes
// the mean without a multiplication or division.
AVS_AVX2_INLINE __m256 fit8(const Window8& w, __m256i c0, const WindowConstants8& k) {
  // Columns that may be fitted: no discontinuity and at least 3 codes (then det > 0 decides).
  const __m256i candidate =
      _mm256_and_si256(_mm256_cmpeq_epi32(w.jumps, k.zero), _mm256_cmpgt_epi32(w.n, k.two));
  const __m256i symmetric = _mm256_cmpeq_epi32(w.sd, k.zero);
  const __m256i complete = _mm256_and_si256(symmetric, _mm256_cmpeq_epi32(w.n, k.full));
  if (_mm256_testc_si256(complete, candidate) != 0) {
    // Every candidate has the complete window (the common case), where det = n sdd > 0.
    return refined8(mean8(w.sc, k), candidate, c0, k);
  }
  const __m256i det =
      _mm256_sub_epi32(_mm256_mullo_epi32(w.n, w.sdd), _mm256_mullo_epi32(w.sd, w.sd));
  const __m256i fit = _mm256_and_si256(candidate, _mm256_cmpgt_epi32(det, k.zero));
  const __m256i divisor = _mm256_blendv_epi8(k.one, _mm256_blendv_epi8(det, w.n, symmetric), fit);
  const __m256i numerator = _mm256_blendv_epi8(
      _mm256_sub_epi32(_mm256_mullo_epi32(w.sc, w.sdd), _mm256_mullo_epi32(w.scd, w.sd)), w.sc,
      symmetric);
  return refined8(_mm256_div_ps(_mm256_cvtepi32_ps(numerator), _mm256_cvtepi32_ps(divisor)), fit,
                  c0, k);
}

// window_step_plain on 8 columns at once (the compiler's own vectorisation of the plain loop ran
// 32 columns wide, for the byte flags, and spilled its sums to the stack).
template <bool kAdd, bool kRemove, bool kOutput>
__attribute__((target("avx2"))) void window_step_avx2(const StepArgs& a) {
  const Sums s = a.s;
  const WindowConstants8 k(a.d_in, a.d_out, a.reach, a.max_jump);
  const __m256i y_in = _mm256_set1_epi32(a.y_in);
  int x = 0;
  for (; x + 8 <= a.width; x += 8) {
    Window8 w{load32(s.n + x),  load32(s.sd + x),  load32(s.sdd + x),
              load32(s.sc + x), load32(s.scd + x), load32(s.jumps + x)};
    if constexpr (kOutput) shift8(w);
    if constexpr (kRemove) {
      remove8(w, load16(a.leaving + x),
              _mm256_cvtepu8_epi32(
                  _mm_loadl_epi64(reinterpret_cast<const __m128i*>(a.leaving_jump + x))),
              k);
    }
    if constexpr (kAdd) {
      __m256i previous = load16(a.previous + x);
      __m256i previous_y = load32(a.previous_y + x);
      const __m128i j16 =
          pack16(add8(w, load16(a.entering + x), y_in, k.d_in16, k.dd_in, previous, previous_y, k));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(a.entering_jump + x), _mm_packs_epi16(j16, j16));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(a.previous + x), pack16(previous));
      store32(a.previous_y + x, previous_y);
    }
    store32(s.n + x, w.n);
    store32(s.sd + x, w.sd);
    store32(s.sdd + x, w.sdd);
    store32(s.sc + x, w.sc);
    store32(s.scd + x, w.scd);
    store32(s.jumps + x, w.jumps);
    if constexpr (kOutput) _mm256_storeu_ps(a.out + x, fit8(w, load16(a.row + x), k));
  }
  _mm256_zeroupper();  // see triangulate_subcode_avx2
  window_step_plain<kAdd, kRemove, kOutput>(a, x);
}

AVS_AVX2_INLINE __m256i word(int v) {
  return _mm256_set1_epi16(static_cast<short>(v));
}
AVS_AVX2_INLINE __m256i load(const std::int16_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
AVS_AVX2_INLINE void store(std::int16_t* p, __m256i v) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v);
}
// 16 int16 lanes as two halves of 8 int32 (sign-extended).
AVS_AVX2_INLINE __m256i widen_low(__m256i v) {
  return _mm256_cvtepi16_epi32(_mm256_castsi256_si128(v));
}
AVS_AVX2_INLINE __m256i widen_high(__m256i v) {
  return _mm256_cvtepi16_epi32(_mm256_extracti128_si256(v, 1));
}

// window_step_plain on 16 columns at once with 16-bit sums of count, code and discontinuities
// (StepArgs::narrow): the same additions modulo 2^16, exact whenever a result is used
// (SubcodeRefiner's bounds). A block whose fitted columns all have the complete window (the
// common case, even with the ken's edges and shadows in view) needs no more: the fit is the
// window's mean. The other blocks (near invalid pixels and the image's top and bottom) take their
// offset sums sd, sdd, scd from the window's rows and the line fit of fit8: no running offset sums
// to move for every block.
template <bool kAdd, bool kRemove, bool kOutput>
__attribute__((target("avx2"))) void window_step_avx2_narrow(const StepArgs& a) {
  const NarrowSums& s = *a.narrow;
  const WindowConstants8 k(a.d_in, a.d_out, a.reach, a.max_jump);
  const __m256i zero = _mm256_setzero_si256();
  const __m256i one = _mm256_set1_epi16(1);
  const __m256i minus_one = _mm256_set1_epi16(-1);
  const __m256i two = word(2);
  const __m256i full = word(a.reach + 1);
  const __m256 full_f = _mm256_set1_ps(static_cast<float>(a.reach + 1));
  const __m256i y_in = word(a.y_in);
  const __m256i beyond = word(a.reach + 1);
  const __m256i max_jump = word(a.max_jump);
  int x = 0;
  for (; x + 16 <= a.width; x += 16) {
    __m256i n = load(s.n + x), sc = load(s.sc + x), jumps = load(s.jumps + x);
    if constexpr (kRemove) {  // as remove8
      const __m256i c = load(a.leaving + x);
      const __m256i valid = _mm256_cmpgt_epi16(c, minus_one);
      n = _mm256_add_epi16(n, valid);
      sc = _mm256_sub_epi16(sc, _mm256_and_si256(valid, c));
      jumps = _mm256_sub_epi16(jumps, _mm256_cvtepu8_epi16(_mm_loadu_si128(
                                          reinterpret_cast<const __m128i*>(a.leaving_jump + x))));
    }
    if constexpr (kAdd) {  // as add8
      const __m256i c = load(a.entering + x);
      const __m256i valid = _mm256_cmpgt_epi16(c, minus_one);
      const __m256i previous = load(a.previous + x);
      const __m256i previous_y = load(a.previous_y16 + x);
      // Saturating: the first previous row is -32768.
      const __m256i gap = _mm256_min_epi16(_mm256_subs_epi16(y_in, previous_y), beyond);
      const __m256i difference = _mm256_sub_epi16(c, previous);
      const __m256i magnitude = _mm256_abs_epi16(difference);
      const __m256i j = _mm256_and_si256(
          _mm256_and_si256(valid, _mm256_cmpgt_epi16(beyond, gap)),
          _mm256_and_si256(_mm256_cmpgt_epi16(magnitude, _mm256_mullo_epi16(max_jump, gap)), one));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(a.entering_jump + x),
                       _mm_packs_epi16(_mm256_castsi256_si128(j), _mm256_extracti128_si256(j, 1)));
      store(a.previous + x, _mm256_add_epi16(previous, _mm256_and_si256(valid, difference)));
      store(a.previous_y16 + x,
            _mm256_add_epi16(previous_y,
                             _mm256_and_si256(valid, _mm256_sub_epi16(y_in, previous_y))));
      n = _mm256_sub_epi16(n, valid);
      sc = _mm256_add_epi16(sc, _mm256_and_si256(valid, c));
      jumps = _mm256_add_epi16(jumps, j);
    }
    store(s.n + x, n);
    store(s.sc + x, sc);
    store(s.jumps + x, jumps);
    if constexpr (kOutput) {
      const __m256i c0 = load(a.row + x);
      // fit8's test on all 16 columns at once. n = 2h + 1 only for a window of 2h + 1 valid
      // rows, whose offsets then sum to 0 (fit8's symmetric case).
      const __m256i candidate =
          _mm256_and_si256(_mm256_cmpeq_epi16(jumps, zero), _mm256_cmpgt_epi16(n, two));
      if (_mm256_testc_si256(_mm256_cmpeq_epi16(n, full), candidate) != 0) {
        // The clamp to the code +- 1 is done on the sum, in 16 bits: mean = clamp(sc, n (c - 1),
        // n (c + 1)) / n, and c = n c / n where there is no fit. One float division of exact
        // integers, so the value is the plain step's clamp(sc / n, c - 1, c + 1) bit for bit
        // (division rounds monotonically and n (c +- 1) / n is exact); all within 16 bits
        // (SubcodeRefiner's bounds).
        const __m256i nc = _mm256_mullo_epi16(c0, full);
        const __m256i clamped = _mm256_max_epi16(_mm256_min_epi16(sc, _mm256_add_epi16(nc, full)),
                                                 _mm256_sub_epi16(nc, full));
        const __m256i sum = _mm256_blendv_epi8(nc, clamped, candidate);
        const __m256i invalid = _mm256_cmpgt_epi16(zero, c0);
        const __m256 low = _mm256_div_ps(_mm256_cvtepi32_ps(widen_low(sum)), full_f);
        const __m256 high = _mm256_div_ps(_mm256_cvtepi32_ps(widen_high(sum)), full_f);
        _mm256_storeu_ps(a.out + x,
                         _mm256_blendv_ps(low, k.nan, _mm256_castsi256_ps(widen_low(invalid))));
        _mm256_storeu_ps(a.out + x + 8,
                         _mm256_blendv_ps(high, k.nan, _mm256_castsi256_ps(widen_high(invalid))));
        continue;
      }
      // The offset sums of the window's valid rows (d = y - y0), in 16 bits: |scd| <= h (h + 1)
      // times the largest code, |sd|, sdd smaller (SubcodeRefiner's bounds), so exact.
      __m256i sd = zero, sdd = zero, scd = zero;
      const std::int16_t* window_row = a.window_first + x;
      for (int r = 0; r < a.window_rows; ++r, window_row += a.width) {
        const int d = a.window_first_d + r;
        const __m256i c = load(window_row);
        const __m256i valid = _mm256_cmpgt_epi16(c, minus_one);
        sd = _mm256_add_epi16(sd, _mm256_and_si256(valid, word(d)));
        sdd = _mm256_add_epi16(sdd, _mm256_and_si256(valid, word(d * d)));
        scd = _mm256_add_epi16(scd, _mm256_mullo_epi16(_mm256_and_si256(valid, c), word(d)));
      }
      _mm256_storeu_ps(a.out + x, fit8(Window8{widen_low(n), widen_low(sd), widen_low(sdd),
                                               widen_low(sc), widen_low(scd), widen_low(jumps)},
                                       widen_low(c0), k));
      _mm256_storeu_ps(a.out + x + 8,
                       fit8(Window8{widen_high(n), widen_high(sd), widen_high(sdd), widen_high(sc),
                                    widen_high(scd), widen_high(jumps)},
                            widen_high(c0), k));
    }
  }
  // The remaining columns with the 32-bit sums (their own columns of SubcodeRefiner's arrays),
  // in SSE code like the caller: clean upper halves first (see triangulate_subcode_avx2).
  _mm256_zeroupper();
  window_step_plain<kAdd, kRemove, kOutput>(a, x);
}
#endif

template <bool kAdd, bool kRemove, bool kOutput = true>
void window_step(const StepArgs& a, KernelIsa isa) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (isa == KernelIsa::kAvx2) {
    if (a.narrow != nullptr) {
      window_step_avx2_narrow<kAdd, kRemove, kOutput>(a);
    } else {
      window_step_avx2<kAdd, kRemove, kOutput>(a);
    }
    return;
  }
#endif
  (void)isa;
  window_step_plain<kAdd, kRemove, kOutput>(a, 0);
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
// kRowRay: ray_y is one value for every pixel (one row of a camera with separable rays).
template <bool kRowRay>
void triangulate_subcode_plain(const float* __restrict refined, const SubcodePlanes& planes,
                               const float* __restrict ray_x, const float* __restrict ray_y,
                               float min_depth_m, float max_depth_m, float* __restrict depth,
                               int begin, int pixels) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (planes.linear != nullptr) {  // LinearSubcodePlanes: its order of operations
    const LinearSubcodePlanes& l = *planes.linear;
    for (int i = begin; i < pixels; ++i) {
      const float u = refined[i];
      const float rx = ray_x[i];
      const float ry = ray_y[kRowRay ? 0 : i];
      const float d0 = l.a0 * rx + (l.b0 * ry + l.c0);
      const float d1 = l.a1 * rx + (l.b1 * ry + l.c1);
      const float z = (l.n0 + u * l.n1) / (d0 + u * d1);
      const bool ok = (u >= l.u_min) & (u <= l.u_max);  // false for NaN
      depth[i] = (ok & (z > min_depth_m) & (z < max_depth_m)) ? z : nan;
    }
    return;
  }
  const auto steps = static_cast<float>(planes.steps);
  const auto count = static_cast<float>(planes.count);
  const float* __restrict table = planes.planes;
  for (int i = begin; i < pixels; ++i) {
    const float position = (refined[i] + 0.5f) * steps + 0.5f;
    const bool ok = (position >= 0.0f) & (position < count);  // false for NaN
    const float* pl = table + 4 * (ok ? static_cast<int>(position) : 0);
    const float z = 1.0f / (pl[0] * ray_x[i] + pl[1] * ray_y[kRowRay ? 0 : i] + pl[2]);
    depth[i] = (ok & (z > min_depth_m) & (z < max_depth_m)) ? z : nan;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
struct TriangulationConstants8 {
  __m256 half, steps, count, zero, one, zmin, zmax, nan;
  const float* table;

  AVS_AVX2_INLINE TriangulationConstants8(const SubcodePlanes& planes, float min_depth_m,
                                          float max_depth_m)
      : half(_mm256_set1_ps(0.5f)),
        steps(_mm256_set1_ps(static_cast<float>(planes.steps))),
        count(_mm256_set1_ps(static_cast<float>(planes.count))),
        zero(_mm256_setzero_ps()),
        one(_mm256_set1_ps(1.0f)),
        zmin(_mm256_set1_ps(min_depth_m)),
        zmax(_mm256_set1_ps(max_depth_m)),
        nan(_mm256_set1_ps(std::numeric_limits<float>::quiet_NaN())),
        table(planes.planes) {}
};

// triangulate_subcode_plain on 8 pixels (fractional codes u, rays rx, ry): the plane rows by
// load_planes8 (a compiler-made gather was scalar), the division exact (vdivps, as divss), no
// fused multiply-add: the same depth as the plain loop.
AVS_AVX2_INLINE __m256 depth8(__m256 u, __m256 rx, __m256 ry, const TriangulationConstants8& t) {
  const __m256 position = _mm256_add_ps(_mm256_mul_ps(_mm256_add_ps(u, t.half), t.steps), t.half);
  const __m256 ok = _mm256_and_ps(_mm256_cmp_ps(position, t.zero, _CMP_GE_OQ),
                                  _mm256_cmp_ps(position, t.count, _CMP_LT_OQ));
  const __m256i index = _mm256_and_si256(_mm256_cvttps_epi32(position), _mm256_castps_si256(ok));
  // The indices out of the register (as the rolling kernel does): a vector store read back as
  // 8 scalars cannot be forwarded on some cores and stalled this loop.
  const __m128i low = _mm256_castsi256_si128(index);
  const __m128i high = _mm256_extracti128_si256(index, 1);
  const auto i01 = static_cast<std::uint64_t>(_mm_cvtsi128_si64(low));
  const auto i23 = static_cast<std::uint64_t>(_mm_extract_epi64(low, 1));
  const auto i45 = static_cast<std::uint64_t>(_mm_cvtsi128_si64(high));
  const auto i67 = static_cast<std::uint64_t>(_mm_extract_epi64(high, 1));
  const float* rows[8] = {t.table + 4 * (i01 & 0xffffffffu), t.table + 4 * (i01 >> 32),
                          t.table + 4 * (i23 & 0xffffffffu), t.table + 4 * (i23 >> 32),
                          t.table + 4 * (i45 & 0xffffffffu), t.table + 4 * (i45 >> 32),
                          t.table + 4 * (i67 & 0xffffffffu), t.table + 4 * (i67 >> 32)};
  const auto [pa, pb, pc] = load_planes8(rows);
  const __m256 den = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(pa, rx), _mm256_mul_ps(pb, ry)), pc);
  const __m256 z = _mm256_div_ps(t.one, den);
  const __m256 keep = _mm256_and_ps(ok, _mm256_and_ps(_mm256_cmp_ps(z, t.zmin, _CMP_GT_OQ),
                                                      _mm256_cmp_ps(z, t.zmax, _CMP_LT_OQ)));
  return _mm256_blendv_ps(t.nan, z, keep);
}

// LinearSubcodePlanes on 8 pixels, the plain loop's operations one for one (no fused
// multiply-add, the division exact).
struct LinearConstants8 {
  __m256 a0, b0, c0, n0, a1, b1, c1, n1, u_min, u_max, zmin, zmax, nan;

  AVS_AVX2_INLINE LinearConstants8(const LinearSubcodePlanes& l, float min_depth_m,
                                   float max_depth_m)
      : a0(_mm256_set1_ps(l.a0)),
        b0(_mm256_set1_ps(l.b0)),
        c0(_mm256_set1_ps(l.c0)),
        n0(_mm256_set1_ps(l.n0)),
        a1(_mm256_set1_ps(l.a1)),
        b1(_mm256_set1_ps(l.b1)),
        c1(_mm256_set1_ps(l.c1)),
        n1(_mm256_set1_ps(l.n1)),
        u_min(_mm256_set1_ps(l.u_min)),
        u_max(_mm256_set1_ps(l.u_max)),
        zmin(_mm256_set1_ps(min_depth_m)),
        zmax(_mm256_set1_ps(max_depth_m)),
        nan(_mm256_set1_ps(std::numeric_limits<float>::quiet_NaN())) {}
};

AVS_AVX2_INLINE __m256 linear_depth8(__m256 u, __m256 rx, __m256 ry, const LinearConstants8& l) {
  const __m256 d0 =
      _mm256_add_ps(_mm256_mul_ps(l.a0, rx), _mm256_add_ps(_mm256_mul_ps(l.b0, ry), l.c0));
  const __m256 d1 =
      _mm256_add_ps(_mm256_mul_ps(l.a1, rx), _mm256_add_ps(_mm256_mul_ps(l.b1, ry), l.c1));
  const __m256 z = _mm256_div_ps(_mm256_add_ps(l.n0, _mm256_mul_ps(u, l.n1)),
                                 _mm256_add_ps(d0, _mm256_mul_ps(u, d1)));
  const __m256 ok =
      _mm256_and_ps(_mm256_cmp_ps(u, l.u_min, _CMP_GE_OQ), _mm256_cmp_ps(u, l.u_max, _CMP_LE_OQ));
  const __m256 keep = _mm256_and_ps(ok, _mm256_and_ps(_mm256_cmp_ps(z, l.zmin, _CMP_GT_OQ),
                                                      _mm256_cmp_ps(z, l.zmax, _CMP_LT_OQ)));
  return _mm256_blendv_ps(l.nan, z, keep);
}

template <bool kRowRay>
__attribute__((target("avx2"))) void triangulate_subcode_avx2(const float* __restrict refined,
                                                              const SubcodePlanes& planes,
                                                              const float* __restrict ray_x,
                                                              const float* __restrict ray_y,
                                                              float min_depth_m, float max_depth_m,
                                                              float* __restrict depth, int pixels) {
  const __m256 row_ray_y = _mm256_set1_ps(ray_y[0]);
  int i = 0;
  if (planes.linear != nullptr) {
    const LinearConstants8 l(*planes.linear, min_depth_m, max_depth_m);
    for (; i + 8 <= pixels; i += 8) {
      _mm256_storeu_ps(depth + i,
                       linear_depth8(_mm256_loadu_ps(refined + i), _mm256_loadu_ps(ray_x + i),
                                     kRowRay ? row_ray_y : _mm256_loadu_ps(ray_y + i), l));
    }
  }
  const TriangulationConstants8 t(planes, min_depth_m, max_depth_m);
  for (; planes.linear == nullptr && i + 8 <= pixels; i += 8) {
    _mm256_storeu_ps(depth + i, depth8(_mm256_loadu_ps(refined + i), _mm256_loadu_ps(ray_x + i),
                                       kRowRay ? row_ray_y : _mm256_loadu_ps(ray_y + i), t));
  }
  // The plain tail and the caller are SSE code: clean upper halves first. GCC 12 left out the
  // vzeroupper here (and in most AVX2 functions of the decoder), and SSE instructions after
  // 256-bit ones with dirty upper halves slowed the per-row calls by 0.07 ms per depth map.
  _mm256_zeroupper();
  triangulate_subcode_plain<kRowRay>(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth,
                                     i, pixels);
}

#endif

}  // namespace

void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels) {
  static const KernelIsa isa = best_kernel_isa();
  triangulate_subcode(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth, pixels, isa);
}

namespace {

template <bool kRowRay>
void triangulate_subcode_with(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                              const float* ray_y, float min_depth_m, float max_depth_m,
                              float* depth, int pixels, KernelIsa isa) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (isa == KernelIsa::kAvx2) {
    triangulate_subcode_avx2<kRowRay>(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m,
                                      depth, pixels);
    return;
  }
#endif
  (void)isa;
  triangulate_subcode_plain<kRowRay>(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth,
                                     0, pixels);
}

}  // namespace

void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels, KernelIsa isa) {
  triangulate_subcode_with<false>(refined, planes, ray_x, ray_y, min_depth_m, max_depth_m, depth,
                                  pixels, isa);
}

void triangulate_subcode_row(const float* refined_row, const SubcodePlanes& planes,
                             const float* column_ray_x, float row_ray_y, float min_depth_m,
                             float max_depth_m, float* depth_row, int width, KernelIsa isa) {
  triangulate_subcode_with<true>(refined_row, planes, column_ray_x, &row_ray_y, min_depth_m,
                                 max_depth_m, depth_row, width, isa);
}

void triangulate_subcode_row(const float* refined_row, const SubcodePlanes& planes,
                             const float* column_ray_x, float row_ray_y, float min_depth_m,
                             float max_depth_m, float* depth_row, int width) {
  static const KernelIsa isa = best_kernel_isa();
  triangulate_subcode_row(refined_row, planes, column_ray_x, row_ray_y, min_depth_m, max_depth_m,
                          depth_row, width, isa);
}

void SubcodeRefiner::refine(const std::int16_t* codes, float* refined, RowSink* sink,
                            RefinedRows rows) {
  if (rows == RefinedRows::kOneRowForAll && sink == nullptr) {
    throw std::invalid_argument("sub-code refinement: one refined row for all needs a row sink");
  }
  const int w = params_.width;
  const int h = params_.height;
  const int half = params_.half_window;
  std::fill(previous_.begin(), previous_.end(), 0);
  std::fill(previous_y_.begin(), previous_y_.end(), std::numeric_limits<std::int32_t>::min() / 2);
  std::fill(n_.begin(), n_.end(), 0);
  std::fill(sd_.begin(), sd_.end(), 0);
  std::fill(sdd_.begin(), sdd_.end(), 0);
  std::fill(sc_.begin(), sc_.end(), 0);
  std::fill(scd_.begin(), scd_.end(), 0);
  std::fill(jumps_.begin(), jumps_.end(), 0);
  const Sums sums{n_.data(), sd_.data(), sdd_.data(), sc_.data(), scd_.data(), jumps_.data()};
  if (narrow_) {
    for (auto* v : {&n16_, &sc16_, &jumps16_}) std::fill(v->begin(), v->end(), std::int16_t{0});
    std::fill(previous_y16_.begin(), previous_y16_.end(), std::numeric_limits<std::int16_t>::min());
  }
  const NarrowSums sums16{n16_.data(), sc16_.data(), jumps16_.data()};
  const NarrowSums* narrow = narrow_ ? &sums16 : nullptr;
  const auto row_of = [&](int y) { return codes + static_cast<std::ptrdiff_t>(y) * w; };
  // A row's flags are read when it leaves the window, 2h + 1 rows after it entered: a ring of
  // 2h + 2 rows (in the cache) holds them.
  const int ring = 2 * half + 2;
  const auto jump_of = [&](int y) {
    return jump_.data() + static_cast<std::ptrdiff_t>(y % ring) * w;
  };
  const int max_jump = params_.max_jump;
  // The window's first h rows enter without an output row, about the origin y0 = -1 that the
  // first output step moves to 0.
  for (int y = 0; y < std::min(half, h); ++y) {
    window_step<true, false, false>(
        StepArgs{row_of(y), jump_of(y), nullptr, nullptr, nullptr, nullptr, previous_.data(),
                 previous_y_.data(), sums, w, y, y + 1, 0, 2 * half, max_jump, narrow,
                 previous_y16_.data()},
        isa_);
  }
  for (int y0 = 0; y0 < h; ++y0) {
    const bool enters = y0 + half < h;
    const bool leaves = y0 - half - 1 >= 0;
    const int y_in = enters ? y0 + half : y0;
    const int y_out = leaves ? y0 - half - 1 : y0;
    auto* step = enters ? (leaves ? &window_step<true, true> : &window_step<true, false>)
                        : (leaves ? &window_step<false, true> : &window_step<false, false>);
    float* out =
        rows == RefinedRows::kAll ? refined + static_cast<std::ptrdiff_t>(y0) * w : refined;
    const int first = std::max(0, y0 - half);
    step(StepArgs{row_of(y_in),
                  jump_of(y_in),
                  row_of(y_out),
                  jump_of(y_out),
                  row_of(y0),
                  out,
                  previous_.data(),
                  previous_y_.data(),
                  sums,
                  w,
                  y_in,
                  half,
                  -half - 1,
                  2 * half,
                  max_jump,
                  narrow,
                  previous_y16_.data(),
                  row_of(first),
                  std::min(h - 1, y0 + half) - first + 1,
                  first - y0},
         isa_);
    if (sink != nullptr) sink->row_done(y0, out);
  }
}

}  // namespace avs::decode::detail
