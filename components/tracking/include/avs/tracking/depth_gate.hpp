// A depth gate around the tracked target (our addition to section 5.1; issue 19, occlusion).
// Eq. 8 takes everything between phi_l and phi_h as the target, so an object that passes in
// front of it inside that window (a board 0.6 m away in front of the ken at 1 m) becomes part of
// the mask, and the head turns toward the mixture. Once a target has been seen, the gate narrows
// the window to the target's last mean depth X_c +- half_width_m (inside phi_l .. phi_h): what
// passes in front or behind is left out. The gate follows the target in depth by at most
// max_step_m per image (a target does not jump in depth; what passes in front must not drag the
// gate to itself). The region too: only pixels within region_scale x sqrt(m00) +
// region_margin_px of the last target's centroid can be target, so the rolling decoder's wrong
// depths along the fast edges of what passes by (anywhere between the occluder's depth and the
// wall's) do not join the mask from afar; the region scales with the target's area, so stray
// pixels cannot widen it. While the gate is closed a mask smaller than min_area_share of the
// target's running area is not the target (the target is hidden; what is left are those wrong
// depths): the gate does not move and the tracker sees no target, so the head holds instead of
// chasing them. After release_frames without a target (hidden, or gone) it opens to Eq. 8's
// window so a target at another depth is found again. I/O-free.
#pragma once

#include "avs/tracking/moments.hpp"

namespace avs::tracking {

struct DepthGateConfig {
  double half_width_m = 0.0;  ///< 0: off (Eq. 8's fixed window, as the paper)
  int release_frames = 250;   ///< images without a target before the gate opens (0.5 s at 500 Hz)
  double max_step_m = 0.01;   ///< largest move of the gate's centre per image (5 m/s at 500 Hz)
  double region_scale = 1.5;  ///< the region's half-size: this x sqrt(m00) ...
  int region_margin_px = 20;  ///< ... plus this many pixels
  /// While closed, a mask below this share of the target's running area (m00 averaged over the
  /// images it was seen whole in, at least 80 % of the average; weight 0.1 for the newest) is no
  /// target.
  double min_area_share = 0.5;
};

class DepthGate {
 public:
  explicit DepthGate(DepthGateConfig config = {}) : config_(config) {}

  /// The window for the next image: Eq. 8's, narrowed around the last target while the gate is
  /// closed.
  [[nodiscard]] MomentsConfig window(const MomentsConfig& eq8) const;
  /// The observation measured in window(): a target (re)centres the gate; release_frames images
  /// without one in a row open it. Returns whether the observation is the target (present, and
  /// while the gate is closed at least min_area_share of the running area); with the gate off,
  /// observation.present.
  [[nodiscard]] bool observe(const TargetObservation& observation);

  [[nodiscard]] bool closed() const { return closed_; }
  [[nodiscard]] double centre_m() const { return centre_m_; }
  void retune(const DepthGateConfig& config);

 private:
  DepthGateConfig config_;
  bool closed_ = false;
  double centre_m_ = 0.0;
  PixelBox region_;
  double area_px_ = 0.0;  // the target's running area
  int absent_frames_ = 0;
};

}  // namespace avs::tracking
