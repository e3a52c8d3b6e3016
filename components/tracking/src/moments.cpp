#include "avs/tracking/moments.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace avs::tracking {
namespace {

constexpr int kBlock = 16;  ///< pixels tested at once for any target pixel

/// Whether any of the kBlock depths at p lies in (lo, hi) (NaN does not).
bool any_within(const float* p, float lo, float hi) {
#if defined(__SSE2__)
  const __m128 low = _mm_set1_ps(lo), high = _mm_set1_ps(hi);
  __m128 any = _mm_setzero_ps();
  for (int k = 0; k < kBlock; k += 4) {
    const __m128 h = _mm_loadu_ps(p + k);
    any = _mm_or_ps(any, _mm_and_ps(_mm_cmplt_ps(low, h), _mm_cmplt_ps(h, high)));
  }
  return _mm_movemask_ps(any) != 0;
#else
  bool any = false;
  for (int k = 0; k < kBlock; ++k) any |= (lo < p[k]) & (p[k] < hi);
  return any;
#endif
}

}  // namespace

TargetObservation measure_target(const geometry::DepthView& depth,
                                 const geometry::CameraModel& camera, const MomentsConfig& config) {
  if (depth.depth_m == nullptr && depth.width_px * depth.height_px != 0) {
    throw std::invalid_argument("measure_target: null depth image of " +
                                std::to_string(depth.width_px) + "x" +
                                std::to_string(depth.height_px));
  }
  const auto stride = static_cast<std::size_t>(depth.stride());
  const float lo = static_cast<float>(config.depth_min_m);
  const float hi = static_cast<float>(config.depth_max_m);
  // Sums per row in integers/floats, then in double: exact for 512x512 images.
  double m00 = 0, m10 = 0, m01 = 0, depth_sum = 0;
  const PixelBox& region = config.region;
  const int u_begin = std::max(0, region.u_min);
  const int u_end = std::min(depth.width_px - 1, region.u_max);
  const int v_begin = std::max(0, region.v_min);
  const int v_end = std::min(depth.height_px - 1, region.v_max);
  PixelBox bounds{std::numeric_limits<int>::max(), -1, std::numeric_limits<int>::max(), -1};
  for (int v = v_begin; v <= v_end; ++v) {
    const float* row = depth.depth_m + static_cast<std::size_t>(v) * stride;
    long count = 0;
    long u_sum = 0;
    double row_depth = 0;
    int first = -1;
    int last = -1;
    // Blocks of 16 pixels without a target pixel (most of the image) are passed after one
    // branch-free test that the compiler vectorises; the others are summed pixel by pixel in
    // the same order as before, so the sums are the same to the last bit.
    for (int u = u_begin; u <= u_end;) {
      const int block_end = std::min(u + kBlock, u_end + 1);
      if (block_end - u == kBlock && !any_within(row + u, lo, hi)) {
        u = block_end;
        continue;
      }
      for (; u < block_end; ++u) {
        const float h = row[u];
        if (lo < h && h < hi) {  // Eq. 8 (NaN compares false)
          ++count;
          u_sum += u;
          row_depth += h;
          if (first < 0) first = u;
          last = u;
        }
      }
    }
    if (count == 0) continue;
    bounds.u_min = std::min(bounds.u_min, first);
    bounds.u_max = std::max(bounds.u_max, last);
    bounds.v_min = std::min(bounds.v_min, v);
    bounds.v_max = v;
    m00 += static_cast<double>(count);
    m10 += static_cast<double>(u_sum) - camera.cx_px * static_cast<double>(count);
    m01 += (v - camera.cy_px) * static_cast<double>(count);
    depth_sum += row_depth;
  }
  TargetObservation obs;
  obs.m00 = m00;
  obs.m10 = m10;
  obs.m01 = m01;
  if (m00 > 0) {
    obs.m_g_px = {m10 / m00, m01 / m00};  // Eq. 9
    obs.centroid_u_px = obs.m_g_px.x() + camera.cx_px;
    obs.centroid_v_px = obs.m_g_px.y() + camera.cy_px;
    if (camera.has_distortion()) {
      // Eq. 10 relates m_g to the target's direction through the pinhole: undistort it.
      const Eigen::Vector2d ideal = camera.undistort_pixel({obs.centroid_u_px, obs.centroid_v_px});
      obs.m_g_px = ideal - Eigen::Vector2d(camera.cx_px, camera.cy_px);
    }
    obs.mean_depth_m = depth_sum / m00;
    obs.bounds = bounds;
  }
  obs.present = m00 > 0 && m00 >= config.min_area_px;
  return obs;
}

}  // namespace avs::tracking
