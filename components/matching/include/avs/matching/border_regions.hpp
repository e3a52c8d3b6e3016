// Surfaces cut by the image border (issue 19, occlusion and clutter): the depth-window pixels
// connected to the border through smooth depth. Something that enters the view from its side,
// such as a board crossing in front of the target, is such a surface; the tracked target, kept
// in the middle by the head, is not. The matching pipeline leaves these pixels out of the
// S-PCD instead of giving up the whole frame. Plain C++, no I/O.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "avs/matching/cloud.hpp"

namespace avs::matching {

class BorderRegions {
 public:
  /// Marks every pixel with min_depth_m <= z <= max_depth_m that is reachable from a border
  /// pixel in that window by 4-neighbour steps whose depths differ by at most max_step_m.
  /// Returns how many pixels it marked; mask() is then 1 for every other pixel (the ones to
  /// keep), valid until the next call.
  std::size_t mark(const DepthView& depth, float min_depth_m, float max_depth_m, float max_step_m);
  const std::uint8_t* keep_mask() const { return keep_.data(); }
  /// |median depth of the marked pixels - median depth of the other depth-window pixels| of
  /// the last mark(), NaN when either set is empty. An occluder in front of the target (or
  /// clutter behind it) is far from the target's depth; a target that is itself cut by the
  /// border, with some of its parts split off by depth steps, is not.
  float depth_separation_m() const { return separation_m_; }

 private:
  float separation_m_ = 0.0F;
  std::vector<float> marked_z_, kept_z_;  ///< scratch for the medians
  std::vector<std::uint8_t> keep_;
  std::vector<std::int32_t> stack_;  ///< flood-fill scratch, kept between frames
};

}  // namespace avs::matching
