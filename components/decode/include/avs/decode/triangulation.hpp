// Triangulation (section 4.2, Eq. 4) with look-up tables built once at start-up, and the
// plain per-pixel 3x3 solve of Eq. 4 as a reference.
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "avs/decode/sensor_geometry.hpp"

namespace avs::decode {

/// The plane of a fractional code u for a projector without distortion, exactly: the plane of
/// projector row v is P_2 - v P_3 (Eq. 4's third row, P = K_p [R | t]) and v is linear in u, so
/// the plane is too. A camera ray (x, y, 1) meets it at depth
///   z = (n0 + u n1) / ((a0 x + (b0 y + c0)) + u (a1 x + (b1 y + c1)))
/// (this order of operations, in float, is the definition every implementation follows), for
/// u in [u_min, u_max] (the coded rows), NaN elsewhere. No 1 / subcode_steps quantisation of u
/// and no table to look up.
struct LinearSubcodePlanes {
  float a0 = 0, b0 = 0, c0 = 0, n0 = 0;
  float a1 = 0, b1 = 0, c1 = 0, n1 = 0;
  float u_min = 0, u_max = 0;
};

/// The paper's look-up table in a form that fits in cache (~2 MiB for 512 x 512): per camera
/// pixel the undistorted ray (x, y, 1); per code the plane through the projector centre and the
/// code's centre row (projector distortion included: the plane is fitted to the undistorted
/// rays of that row's pixels). Depth along the camera z axis is then z = 1 / (a x + b y + c).
class DepthTable {
 public:
  /// subcode_steps > 0 also builds the sub-code planes (subcode_planes()).
  explicit DepthTable(const SensorGeometry& geometry, int subcode_steps = 0);

  int width() const { return width_; }
  int height() const { return height_; }
  int pixel_count() const { return width_ * height_; }
  /// Index of the all-NaN plane used for invalid pixels (= 2^bit_count).
  int invalid_index() const { return invalid_index_; }

  const float* ray_x() const { return ray_x_.data(); }
  const float* ray_y() const { return ray_y_.data(); }
  /// When every pixel's ray x depends on its column only and its ray y on its row only (checked
  /// exactly, e.g. a camera without distortion): the x of one row (width floats) and the y of
  /// one column (height floats), the same values as ray_x()/ray_y(); null otherwise. The kernel
  /// then reads 8 bytes per pixel less.
  const float* column_ray_x() const {
    return column_ray_x_.empty() ? nullptr : column_ray_x_.data();
  }
  const float* row_ray_y() const { return row_ray_y_.empty() ? nullptr : row_ray_y_.data(); }
  /// 4 floats (a, b, c, 0) per binary code 0 .. 2^n, 16-byte aligned; codes >= code_count and
  /// the last entry are NaN so that their depth is NaN.
  const float* planes() const { return planes_.data(); }

  /// Depth of `pixel_index` (row-major) for binary `code`, same arithmetic as the fast kernel.
  float depth(int pixel_index, int code) const {
    const float* pl = planes_.data() + 4 * code;
    return 1.0f / (pl[0] * ray_x_[pixel_index] + pl[1] * ray_y_[pixel_index] + pl[2]);
  }

  /// Sub-code planes for a fractional code u (projector row first_row + rows_per_code * u +
  /// (rows_per_code - 1) / 2, i.e. u = c is code c's centre row as planes() uses): entry j is
  /// the plane at u = j / subcode_steps() - 1/2, j = 0 .. code_count * subcode_steps(), 4 floats
  /// (a, b, c, 0) each. Empty unless built with subcode_steps > 0.
  const float* subcode_planes() const {
    return subcode_planes_.empty() ? nullptr : subcode_planes_.data();
  }
  int subcode_steps() const { return subcode_steps_; }
  /// With sub-code planes and a projector without distortion: the same planes in closed form
  /// (what the decoder uses then); null otherwise.
  const LinearSubcodePlanes* linear_subcode_planes() const {
    return has_linear_subcode_planes_ ? &linear_subcode_planes_ : nullptr;
  }
  int subcode_plane_count() const { return static_cast<int>(subcode_planes_.size() / 4); }
  /// Largest distance (m) between a fitted plane and the rays of its row, over all codes: 0
  /// without projector distortion; reported so that callers can see the plane approximation.
  double max_plane_fit_error() const { return max_plane_fit_error_; }

 private:
  int width_ = 0;
  int height_ = 0;
  int invalid_index_ = 0;
  std::vector<float> ray_x_;
  std::vector<float> ray_y_;
  std::vector<float> planes_;
  std::vector<float> column_ray_x_;
  std::vector<float> row_ray_y_;
  double max_plane_fit_error_ = 0;
  int subcode_steps_ = 0;
  std::vector<float> subcode_planes_;
  bool has_linear_subcode_planes_ = false;
  LinearSubcodePlanes linear_subcode_planes_;

  static double subcode_row(const SensorGeometry& g, double code);
  /// Plane through the projector centre and projector row `row` (fitted to every column_step-th
  /// column's ray) as (a, b, c, 0) with 1 / z = a x + b y + c; leaves NaN when it passes through
  /// the camera centre. Raises *max_fit_error to the worst ray's sine to the plane.
  static void fit_row_plane(const SensorGeometry& g, double row, int column_step, float* abc0,
                            double* max_fit_error);
};

/// Eq. 4 solved per pixel: F r_c = R with the undistorted camera pixel (x_c, y_c) and the
/// projector row y_p at the code's centre. Projector distortion is ignored (Eq. 4 is a pinhole
/// model), so this is exact only for a distortion-free projector.
class ReferenceTriangulator {
 public:
  explicit ReferenceTriangulator(const SensorGeometry& geometry);

  /// Point in the camera frame (m), NaN components when F is singular or code is invalid.
  Eigen::Vector3d point(int pixel_index, int code) const;
  float depth(int pixel_index, int code) const {
    return static_cast<float>(point(pixel_index, code).z());
  }

 private:
  Eigen::Matrix<double, 3, 4> C_;
  Eigen::Matrix<double, 3, 4> P_;
  int code_count_ = 0;
  std::vector<double> row_of_code_;
  std::vector<Eigen::Vector2d> undistorted_pixel_;  ///< (x_c, y_c) per pixel, distortion removed
};

}  // namespace avs::decode
