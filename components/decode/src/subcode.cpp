#include "subcode.hpp"

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

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
// Plain loops over arrays: the compiler vectorises them; with AVX2 when the CPU has it (the
// default build has no -march flag).
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

// Row y enters the window: its discontinuity flags (against the previous valid code of each
// column, at most 2h rows up) are computed and stored, and its codes added to the sums.
AVS_SUBCODE_CLONES void add_row(const std::int16_t* __restrict row, std::uint8_t* __restrict jump,
                                std::int16_t* __restrict previous,
                                std::int32_t* __restrict previous_y, Sums s, int width, int y,
                                int reach, int max_jump) {
  for (int x = 0; x < width; ++x) {
    // Branch-free (bitwise &, blends by multiplication) so that the loop vectorises.
    const std::int32_t c = row[x];
    const auto valid = static_cast<std::int32_t>(c >= 0);
    const std::int32_t gap = std::min(y - previous_y[x], reach + 1);  // no overflow below
    const std::int32_t difference = c - previous[x];
    const std::int32_t magnitude = std::abs(difference);
    const std::int32_t j = valid & static_cast<std::int32_t>(gap <= reach) &
                           static_cast<std::int32_t>(magnitude > max_jump * gap);
    jump[x] = static_cast<std::uint8_t>(j);
    previous[x] = static_cast<std::int16_t>(previous[x] + valid * difference);
    previous_y[x] += valid * (y - previous_y[x]);
    const std::int32_t vc = valid * c;
    s.n[x] += valid;
    s.sy[x] += valid * y;
    s.syy[x] += valid * y * y;
    s.sc[x] += vc;
    s.scy[x] += vc * y;
    s.jumps[x] += j;
  }
}

// Row y leaves the window.
AVS_SUBCODE_CLONES void remove_row(const std::int16_t* __restrict row,
                                   const std::uint8_t* __restrict jump, Sums s, int width, int y) {
  for (int x = 0; x < width; ++x) {
    const std::int32_t c = row[x];
    const auto valid = static_cast<std::int32_t>(c >= 0);
    const std::int32_t vc = valid * c;
    s.n[x] -= valid;
    s.sy[x] -= valid * y;
    s.syy[x] -= valid * y * y;
    s.sc[x] -= vc;
    s.scy[x] -= vc * y;
    s.jumps[x] -= jump[x];
  }
}

// Line fit about y0 from the window sums (exact integers, d = y - y0); its value at d = 0,
// clamped to the pixel's code +- 1, else the code itself.
AVS_SUBCODE_CLONES void output_row(const std::int16_t* __restrict row, float* __restrict out,
                                   Sums s, int width, int y0) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int x = 0; x < width; ++x) {
    const std::int32_t c0 = row[x];
    const std::int32_t n = s.n[x];
    const std::int32_t sd = s.sy[x] - n * y0;
    const std::int32_t sdd = s.syy[x] - 2 * y0 * s.sy[x] + n * y0 * y0;
    const std::int32_t scd = s.scy[x] - y0 * s.sc[x];
    const std::int32_t det = n * sdd - sd * sd;
    const std::int32_t fit = static_cast<std::int32_t>(s.jumps[x] == 0) &
                             static_cast<std::int32_t>(n >= 3) & static_cast<std::int32_t>(det > 0);
    const auto c = static_cast<float>(c0);
    const std::int32_t divisor = fit * det + (1 - fit);
    const float intercept =
        static_cast<float>(s.sc[x] * sdd - scd * sd) / static_cast<float>(divisor);
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

AVS_SUBCODE_CLONES void triangulate_subcode(const float* __restrict refined,
                                            const SubcodePlanes& planes,
                                            const float* __restrict ray_x,
                                            const float* __restrict ray_y, float min_depth_m,
                                            float max_depth_m, float* __restrict depth,
                                            int pixels) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto steps = static_cast<float>(planes.steps);
  const auto count = static_cast<float>(planes.count);
  const float* __restrict table = planes.planes;
  for (int i = 0; i < pixels; ++i) {
    const float position = (refined[i] + 0.5f) * steps + 0.5f;
    const bool ok = (position >= 0.0f) & (position < count);  // false for NaN
    const float* pl = table + 4 * (ok ? static_cast<int>(position) : 0);
    const float z = 1.0f / (pl[0] * ray_x[i] + pl[1] * ray_y[i] + pl[2]);
    depth[i] = (ok & (z > min_depth_m) & (z < max_depth_m)) ? z : nan;
  }
}

void SubcodeRefiner::refine(const std::int16_t* codes, float* refined) {
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
  const auto add = [&](int y) {
    add_row(row_of(y), jump_of(y), previous_.data(), previous_y_.data(), sums, w, y, 2 * half,
            params_.max_jump);
  };
  for (int y = 0; y < std::min(half, h); ++y) add(y);
  for (int y0 = 0; y0 < h; ++y0) {
    if (y0 + half < h) add(y0 + half);
    if (y0 - half - 1 >= 0)
      remove_row(row_of(y0 - half - 1), jump_of(y0 - half - 1), sums, w, y0 - half - 1);
    output_row(row_of(y0), refined + static_cast<std::ptrdiff_t>(y0) * w, sums, w, y0);
  }
}

}  // namespace avs::decode::detail
