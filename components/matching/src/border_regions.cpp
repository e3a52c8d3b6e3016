// Border-connected depth regions; see border_regions.hpp.
#include "avs/matching/border_regions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace avs::matching {

std::size_t BorderRegions::mark(const DepthView& depth, float min_depth_m, float max_depth_m,
                                float max_step_m) {
  const int w = depth.width_px, h = depth.height_px;
  const int stride = depth.stride_px > 0 ? depth.stride_px : w;
  keep_.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 1);
  if (w <= 0 || h <= 0 || depth.depth_m == nullptr) return 0;
  const auto z_at = [&](int u, int v) {
    return depth.depth_m[static_cast<std::ptrdiff_t>(v) * stride + u];
  };
  const auto in_window = [&](float z) { return z >= min_depth_m && z <= max_depth_m; };
  std::size_t marked = 0;
  stack_.clear();
  const auto seed = [&](int u, int v) {
    const std::size_t i = static_cast<std::size_t>(v) * w + u;
    if (keep_[i] && in_window(z_at(u, v))) {
      keep_[i] = 0;
      ++marked;
      stack_.push_back(static_cast<std::int32_t>(i));
    }
  };
  for (int u = 0; u < w; ++u) seed(u, 0), seed(u, h - 1);
  for (int v = 1; v + 1 < h; ++v) seed(0, v), seed(w - 1, v);
  while (!stack_.empty()) {
    const auto i = static_cast<std::size_t>(stack_.back());
    stack_.pop_back();
    const int u = static_cast<int>(i % static_cast<std::size_t>(w));
    const int v = static_cast<int>(i / static_cast<std::size_t>(w));
    const float z = z_at(u, v);
    const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int nu = u + du[k], nv = v + dv[k];
      if (nu < 0 || nv < 0 || nu >= w || nv >= h) continue;
      const std::size_t n = static_cast<std::size_t>(nv) * w + nu;
      if (!keep_[n]) continue;
      const float nz = z_at(nu, nv);
      if (!in_window(nz) || !(std::abs(nz - z) <= max_step_m)) continue;
      keep_[n] = 0;
      ++marked;
      stack_.push_back(static_cast<std::int32_t>(n));
    }
  }
  marked_z_.clear();
  kept_z_.clear();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float z = z_at(u, v);
      if (!in_window(z)) continue;
      (keep_[static_cast<std::size_t>(v) * w + u] ? kept_z_ : marked_z_).push_back(z);
    }
  }
  const auto median = [](std::vector<float>& z) {
    const auto middle = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2);
    std::nth_element(z.begin(), middle, z.end());
    return *middle;
  };
  separation_m_ = marked_z_.empty() || kept_z_.empty()
                      ? std::numeric_limits<float>::quiet_NaN()
                      : std::abs(median(marked_z_) - median(kept_z_));
  return marked;
}

}  // namespace avs::matching
