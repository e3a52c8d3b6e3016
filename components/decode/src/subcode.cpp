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

void SubcodeRefiner::add_row(const std::int16_t* codes, int y, int sign) {
  const int w = params_.width;
  const std::int16_t* row = codes + static_cast<std::ptrdiff_t>(y) * w;
  const std::uint8_t* jump = jump_.data() + static_cast<std::ptrdiff_t>(y) * w;
  for (int x = 0; x < w; ++x) {
    const std::int32_t c = row[x];
    const std::int32_t v = c >= 0 ? sign : 0;
    n_[x] += v;
    sy_[x] += v * y;
    syy_[x] += v * y * y;
    sc_[x] += v * c;
    scy_[x] += v * c * y;
    jumps_[x] += sign * jump[x];
  }
}

void SubcodeRefiner::refine(const std::int16_t* codes, float* refined) {
  const int w = params_.width;
  const int h = params_.height;
  const int half = params_.half_window;
  const float nan = std::numeric_limits<float>::quiet_NaN();

  // Discontinuities: a valid code whose previous valid code in the column (at most 2h rows up)
  // differs by more than max_jump per row between them.
  std::fill(previous_y_.begin(), previous_y_.end(), std::numeric_limits<std::int32_t>::min() / 2);
  for (int y = 0; y < h; ++y) {
    const std::int16_t* row = codes + static_cast<std::ptrdiff_t>(y) * w;
    std::uint8_t* jump = jump_.data() + static_cast<std::ptrdiff_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      const int c = row[x];
      const int gap = y - previous_y_[x];
      const bool near = gap <= 2 * half;
      jump[x] = static_cast<std::uint8_t>(c >= 0 && near &&
                                          std::abs(c - previous_[x]) > params_.max_jump * gap);
      if (c >= 0) {
        previous_[x] = static_cast<std::int16_t>(c);
        previous_y_[x] = y;
      }
    }
  }

  std::fill(n_.begin(), n_.end(), 0);
  std::fill(sy_.begin(), sy_.end(), 0);
  std::fill(syy_.begin(), syy_.end(), 0);
  std::fill(sc_.begin(), sc_.end(), 0);
  std::fill(scy_.begin(), scy_.end(), 0);
  std::fill(jumps_.begin(), jumps_.end(), 0);
  for (int y = 0; y < std::min(half, h); ++y) add_row(codes, y, 1);
  for (int y0 = 0; y0 < h; ++y0) {
    if (y0 + half < h) add_row(codes, y0 + half, 1);
    if (y0 - half - 1 >= 0) add_row(codes, y0 - half - 1, -1);
    const std::int16_t* row = codes + static_cast<std::ptrdiff_t>(y0) * w;
    float* out = refined + static_cast<std::ptrdiff_t>(y0) * w;
    for (int x = 0; x < w; ++x) {
      const std::int32_t c0 = row[x];
      // Line fit about y0 from the window sums (exact integers): d = y - y0.
      const std::int32_t n = n_[x];
      const std::int32_t sd = sy_[x] - n * y0;
      const std::int32_t sdd = syy_[x] - 2 * y0 * sy_[x] + n * y0 * y0;
      const std::int32_t scd = scy_[x] - y0 * sc_[x];
      const std::int32_t det = n * sdd - sd * sd;
      const bool fit = jumps_[x] == 0 && n >= 3 && det > 0;
      const float c = static_cast<float>(c0);
      const float intercept =
          static_cast<float>(sc_[x] * sdd - scd * sd) / static_cast<float>(fit ? det : 1);
      const float u = fit ? std::clamp(intercept, c - 1.0f, c + 1.0f) : c;
      out[x] = c0 >= 0 ? u : nan;
    }
  }
}

}  // namespace avs::decode::detail
