// Point cloud and camera types shared by the matching core (paper section 6).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "avs/geometry/camera_model.hpp"
#include "avs/geometry/depth_view.hpp"

namespace avs::matching {

/// A point cloud: positions in metres, in the frame named by the variable (p_camera, p_model).
using Points = std::vector<Eigen::Vector3f>;

/// A depth image borrowed from its owner (z of pixel (u, v) in metres, 0 or non-finite where
/// nothing was measured): the project's one depth view type.
using geometry::DepthView;

/// Optional target mask, same layout as the depth image: non-zero = pixel belongs to the target.
struct MaskView {
  const std::uint8_t* mask = nullptr;  ///< nullptr: every pixel with depth is used
  int stride_px = 0;                   ///< 0 means the depth image's width
};

}  // namespace avs::matching
