// The kendama "ken" of the paper (sections 7.1 and 7.2.1): handle, crosspiece (sarado) with
// the big cup (ozara) and the visibly smaller cup (kozara) at its two ends, the bottom cup
// (chuzara) and the spike (kensaki); 180 mm from the bottom cup's rim to the spike tip.
//
// Ken frame (our choice; the paper's Figure 12a is not reproduced in our text): origin on
// the handle axis at the centre of the crosspiece; +Y along the handle towards the spike;
// +X along the crosspiece towards the big cup; Z = X x Y. With this frame a rotation of
// 180 degrees about Y swaps the big and the small cup and nothing else, the confusion the
// paper reports in section 7.2.1.
#pragma once

#include "avs/geometry/mesh.hpp"

namespace avs::geometry {

/// Every dimension of the built-in ken, in metres (docs/sim.md lists them).
struct KenDimensions {
  double spike_tip_y_m = 0.065;          ///< top of the spike
  double bottom_rim_y_m = -0.115;        ///< lowest point: rim of the bottom cup
  double handle_radius_max_m = 0.0125;   ///< widest part of the handle
  double handle_neck_radius_m = 0.0095;  ///< narrowest part above the bottom cup
  double bottom_cup_radius_m = 0.0215;   ///< outer rim radius of the bottom cup (43 mm)
  double crosspiece_radius_m = 0.0135;   ///< crosspiece body radius at its centre
  double big_cup_radius_m = 0.024;       ///< outer rim radius of the big cup (48 mm)
  double big_cup_rim_x_m = 0.042;        ///< big cup rim, +X end
  double small_cup_radius_m = 0.0175;    ///< outer rim radius of the small cup (35 mm)
  double small_cup_rim_x_m = -0.038;     ///< small cup rim, -X end
  double spike_base_radius_m = 0.0095;   ///< spike shoulder just above the crosspiece
  double cup_depth_m = 0.005;            ///< depth of every cup's dish
  int segments = 48;                     ///< steps around each axis of revolution
};

/// Builds the ken from three closed surfaces of revolution (handle with bottom cup,
/// crosspiece with both cups, spike) that overlap slightly where they join.
Mesh make_ken(const KenDimensions& dimensions = {});

}  // namespace avs::geometry
