// Target observation from a depth image (paper section 5.1): binary mask A from the depth
// window phi_l < h_c < phi_h (Eq. 8), moments m00, m10, m01 (Eq. 7), centroid m_g (Eq. 9),
// and the mean target depth X_c used by the image Jacobian (Eq. 15).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "avs/geometry/camera_model.hpp"
#include "avs/geometry/depth_view.hpp"

namespace avs::tracking {

/// Pixels u_min <= u <= u_max, v_min <= v <= v_max (the whole image by default).
struct PixelBox {
  int u_min = 0;
  int u_max = std::numeric_limits<int>::max();
  int v_min = 0;
  int v_max = std::numeric_limits<int>::max();
};

struct MomentsConfig {
  double depth_min_m = 0.3;  ///< phi_l (Eq. 8)
  double depth_max_m = 1.5;  ///< phi_h (Eq. 8)
  double min_area_px = 50;   ///< m00 below this: no target
  /// Only these pixels can be target (our addition: the DepthGate's region around the last
  /// target; the paper's mask is the whole image).
  PixelBox region;
};

struct TargetObservation {
  bool present = false;  ///< m00 >= min_area_px
  double m00 = 0;        ///< area in pixels (Eq. 7, k = l = 0)
  double m10 = 0;        ///< sum of x_c over the mask, x_c = u - cx (pixels)
  double m01 = 0;        ///< sum of y_c over the mask, y_c = v - cy (pixels)
  /// Centroid m_g = [m10/m00, m01/m00] (Eq. 9) relative to the principal point, pixels of the
  /// ideal pinhole (lens distortion removed from the centroid, so Eq. 10 holds).
  Eigen::Vector2d m_g_px = Eigen::Vector2d::Zero();
  double centroid_u_px = 0;  ///< the mask's centroid in image pixels (u right, v down)
  double centroid_v_px = 0;
  double mean_depth_m = 0;  ///< X_c: mean depth over the mask
  PixelBox bounds;          ///< the mask's bounding box (when m00 > 0)
};

/// Eqs. 7-9 over the whole image (NaN, or any value outside the window, is not target). Pixel
/// centres are at integer (u, v). The moments are sums over image pixels; with lens distortion, m_g
/// is the undistorted centroid.
TargetObservation measure_target(const geometry::DepthView& depth,
                                 const geometry::CameraModel& camera, const MomentsConfig& config);

}  // namespace avs::tracking
