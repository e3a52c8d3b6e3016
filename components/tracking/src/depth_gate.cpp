#include "avs/tracking/depth_gate.hpp"

#include <algorithm>
#include <cmath>

namespace avs::tracking {

MomentsConfig DepthGate::window(const MomentsConfig& eq8) const {
  if (!closed_ || !(config_.half_width_m > 0.0)) return eq8;
  MomentsConfig gated = eq8;
  gated.depth_min_m = std::max(eq8.depth_min_m, centre_m_ - config_.half_width_m);
  gated.depth_max_m = std::min(eq8.depth_max_m, centre_m_ + config_.half_width_m);
  // A target drifting out of Eq. 8's window: the gate never lies outside it.
  if (!(gated.depth_min_m < gated.depth_max_m)) return eq8;
  gated.region = region_;
  return gated;
}

bool DepthGate::observe(const TargetObservation& observation) {
  if (!(config_.half_width_m > 0.0)) {
    closed_ = false;
    return observation.present;
  }
  const bool target = observation.present && std::isfinite(observation.mean_depth_m) &&
                      (!closed_ || observation.m00 >= config_.min_area_share * area_px_);
  if (target) {
    if (closed_) {
      const double step = observation.mean_depth_m - centre_m_;
      centre_m_ += std::clamp(step, -config_.max_step_m, config_.max_step_m);
      // The running area follows a target that grows or recedes, not one being hidden (a
      // shrinking remnant would lower the bar for the next).
      if (observation.m00 >= 0.8 * area_px_) area_px_ += 0.1 * (observation.m00 - area_px_);
    } else {
      centre_m_ = observation.mean_depth_m;
      area_px_ = observation.m00;
    }
    closed_ = true;
    const double half =
        config_.region_scale * std::sqrt(observation.m00) + config_.region_margin_px;
    region_ = {static_cast<int>(std::floor(observation.centroid_u_px - half)),
               static_cast<int>(std::ceil(observation.centroid_u_px + half)),
               static_cast<int>(std::floor(observation.centroid_v_px - half)),
               static_cast<int>(std::ceil(observation.centroid_v_px + half))};
    absent_frames_ = 0;
    return true;
  }
  if (closed_ && ++absent_frames_ >= config_.release_frames) {
    closed_ = false;
    absent_frames_ = 0;
  }
  return false;
}

void DepthGate::retune(const DepthGateConfig& config) {
  config_ = config;
  if (!(config_.half_width_m > 0.0)) closed_ = false;
}

}  // namespace avs::tracking
