// The one camera model of avs, for the camera and the projector alike: pinhole intrinsics plus
// OpenCV's lens distortion (k1 k2 p1 p2 k3, optionally the rational k4 k5 k6), pixel centres at
// integer coordinates. The calibration file (decode::load_sensor_geometry_yaml) and
// sensor_msgs/CameraInfo (avs/msg/camera_info.hpp) are its two serialisations; nothing else in
// the project keeps a focal length or a principal point.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace avs::geometry {

/// Pinhole intrinsics plus lens distortion. Pixel centres are at integer coordinates
/// (OpenCV convention): the image spans [-0.5, width - 0.5] x [-0.5, height - 0.5]. The device
/// frame has x right, y down, z forward (optical frame).
struct CameraModel {
  int width = 0;   ///< pixels
  int height = 0;  ///< pixels
  double fx_px = 0, fy_px = 0, cx_px = 0, cy_px = 0;
  /// OpenCV order. radial = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6).
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0, k4 = 0, k5 = 0, k6 = 0;

  Eigen::Matrix3d intrinsic_matrix() const;
  bool has_distortion() const {
    return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0 || is_rational();
  }
  bool is_rational() const { return k4 != 0 || k5 != 0 || k6 != 0; }

  /// ROS's name of the distortion model: "plumb_bob" (5 coefficients) or
  /// "rational_polynomial" (8).
  const char* distortion_model() const {
    return is_rational() ? "rational_polynomial" : "plumb_bob";
  }
  /// k1 k2 p1 p2 k3 [k4 k5 k6]: 5 for plumb_bob, 8 for rational_polynomial.
  std::vector<double> distortion_coefficients() const;
  /// The same into `out` without an allocation (a CameraInfo per depth map); returns the count.
  std::size_t distortion_coefficients(std::array<double, 8>& out) const;
  /// From 0, 4, 5 or 8 coefficients in OpenCV order (the missing ones are 0); returns false
  /// (and changes nothing) for any other count.
  bool set_distortion_coefficients(std::span<const double> d);

  /// Empty when the model is usable; otherwise what is wrong (sizes, focal lengths, finite
  /// values), for error messages.
  std::string problem() const;

  /// Ideal normalised coordinates (x/z, y/z) -> distorted normalised coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& xy_ideal) const;
  /// Inverse of distort(), iteratively (converges for the moderate distortion of real lenses).
  Eigen::Vector2d undistort(const Eigen::Vector2d& xy_distorted) const;

  /// Point in this device's frame (metres, z forward) -> pixel, with distortion.
  Eigen::Vector2d project(const Eigen::Vector3d& p_device) const;
  /// Pixel (u, v) -> ray direction (x, y, 1) in this device's frame, distortion removed.
  Eigen::Vector3d ray(double u_px, double v_px) const;
  /// Pixel -> ideal (undistorted) pixel of the same pinhole: K * undistort(K^-1 (u, v)).
  Eigen::Vector2d undistort_pixel(const Eigen::Vector2d& uv_px) const;
  /// The pixel lies on the image: [-0.5, width - 0.5) x [-0.5, height - 0.5).
  bool contains(const Eigen::Vector2d& uv_px) const {
    return uv_px.x() >= -0.5 && uv_px.x() < width - 0.5 && uv_px.y() >= -0.5 &&
           uv_px.y() < height - 0.5;
  }

  bool operator==(const CameraModel&) const = default;
};

}  // namespace avs::geometry
