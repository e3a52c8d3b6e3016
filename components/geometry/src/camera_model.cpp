#include "avs/geometry/camera_model.hpp"

#include <cmath>

namespace avs::geometry {

Eigen::Matrix3d CameraModel::intrinsic_matrix() const {
  Eigen::Matrix3d K;
  K << fx_px, 0, cx_px, 0, fy_px, cy_px, 0, 0, 1;
  return K;
}

std::size_t CameraModel::distortion_coefficients(std::array<double, 8>& out) const {
  out = {k1, k2, p1, p2, k3, k4, k5, k6};
  return is_rational() ? 8 : 5;
}

std::vector<double> CameraModel::distortion_coefficients() const {
  std::array<double, 8> d;
  const std::size_t n = distortion_coefficients(d);
  return {d.begin(), d.begin() + static_cast<std::ptrdiff_t>(n)};
}

bool CameraModel::set_distortion_coefficients(std::span<const double> d) {
  if (d.size() != 0 && d.size() != 4 && d.size() != 5 && d.size() != 8) return false;
  double* fields[8] = {&k1, &k2, &p1, &p2, &k3, &k4, &k5, &k6};
  for (std::size_t i = 0; i < 8; ++i) *fields[i] = i < d.size() ? d[i] : 0.0;
  return true;
}

std::string CameraModel::problem() const {
  if (width <= 0 || height <= 0) {
    return "image size " + std::to_string(width) + "x" + std::to_string(height) +
           " (expected positive)";
  }
  if (!(fx_px > 0) || !(fy_px > 0) || !std::isfinite(fx_px) || !std::isfinite(fy_px)) {
    return "focal lengths fx " + std::to_string(fx_px) + ", fy " + std::to_string(fy_px) +
           " px (expected positive and finite)";
  }
  for (const double v : {cx_px, cy_px, k1, k2, p1, p2, k3, k4, k5, k6}) {
    if (!std::isfinite(v)) return "principal point or distortion not finite";
  }
  return {};
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  if (is_rational()) radial /= 1 + r2 * (k4 + r2 * (k5 + r2 * k6));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& xy_distorted) const {
  if (!has_distortion()) return xy_distorted;
  // Fixed-point iteration as in OpenCV's undistortPoints, run to convergence.
  Eigen::Vector2d xy = xy_distorted;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Eigen::Vector2d residual = distort(xy) - xy_distorted;
    xy -= residual;
    if (residual.squaredNorm() < 1e-26) break;
  }
  return xy;
}

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d xy = distort(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  return {fx_px * xy.x() + cx_px, fy_px * xy.y() + cy_px};
}

Eigen::Vector3d CameraModel::ray(double u_px, double v_px) const {
  const Eigen::Vector2d xy =
      undistort(Eigen::Vector2d((u_px - cx_px) / fx_px, (v_px - cy_px) / fy_px));
  return {xy.x(), xy.y(), 1.0};
}

Eigen::Vector2d CameraModel::undistort_pixel(const Eigen::Vector2d& uv) const {
  if (!has_distortion()) return uv;
  const Eigen::Vector3d r = ray(uv.x(), uv.y());
  return {fx_px * r.x() + cx_px, fy_px * r.y() + cy_px};
}

}  // namespace avs::geometry
