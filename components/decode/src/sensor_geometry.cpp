#include "avs/decode/sensor_geometry.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace avs::decode {

Eigen::Matrix3d LensModel::intrinsic_matrix() const {
  Eigen::Matrix3d K;
  K << fx_px, 0, cx_px, 0, fy_px, cy_px, 0, 0, 1;
  return K;
}

Eigen::Vector2d LensModel::distort(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d LensModel::undistort(const Eigen::Vector2d& xy_distorted) const {
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

Eigen::Vector2d LensModel::project(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d xy = distort(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  return {fx_px * xy.x() + cx_px, fy_px * xy.y() + cy_px};
}

Eigen::Vector3d LensModel::ray(double u_px, double v_px) const {
  const Eigen::Vector2d xy =
      undistort(Eigen::Vector2d((u_px - cx_px) / fx_px, (v_px - cy_px) / fy_px));
  return {xy.x(), xy.y(), 1.0};
}

Eigen::Matrix<double, 3, 4> SensorGeometry::camera_matrix() const {
  Eigen::Matrix<double, 3, 4> Rt = Eigen::Matrix<double, 3, 4>::Zero();
  Rt.leftCols<3>().setIdentity();
  return camera.intrinsic_matrix() * Rt;
}

Eigen::Matrix<double, 3, 4> SensorGeometry::projector_matrix() const {
  Eigen::Matrix<double, 3, 4> Rt;
  Rt.leftCols<3>() = R_projector_camera;
  Rt.col(3) = t_projector_camera_m;
  return projector.intrinsic_matrix() * Rt;
}

Eigen::Vector3d SensorGeometry::projector_centre_camera_m() const {
  return -R_projector_camera.transpose() * t_projector_camera_m;
}

double SensorGeometry::code_centre_row(int code) const {
  return layout.first_row + layout.rows_per_code * code + 0.5 * (layout.rows_per_code - 1);
}

SensorGeometry default_sensor_geometry() {
  using Spec = DefaultGeometrySpec;
  SensorGeometry g;
  const double half_fov_rad = 0.5 * Spec::camera_vertical_fov_deg * std::numbers::pi / 180.0;
  const double f_camera_px = 0.5 * Spec::camera_height / std::tan(half_fov_rad);
  g.camera.width = Spec::camera_width;
  g.camera.height = Spec::camera_height;
  g.camera.fx_px = g.camera.fy_px = f_camera_px;
  g.camera.cx_px = 0.5 * (Spec::camera_width - 1);
  g.camera.cy_px = 0.5 * (Spec::camera_height - 1);

  const double f_projector_px = Spec::projector_throw_ratio * Spec::projector_width;
  g.projector.width = Spec::projector_width;
  g.projector.height = Spec::projector_height;
  g.projector.fx_px = g.projector.fy_px = f_projector_px;
  g.projector.cx_px = 0.5 * (Spec::projector_width - 1);
  g.projector.cy_px = 0.5 * (Spec::projector_height - 1);

  g.layout = CodeLayout{};  // 9 bits, 265 codes, 4 rows per code
  g.layout.first_row = (Spec::projector_height - g.layout.used_rows()) / 2;  // 40

  // Projector centre below the camera (camera +y) by the baseline, its optical axis aimed at
  // the point on the camera axis at the convergence distance; its rows parallel to camera x.
  const Eigen::Vector3d centre_camera(0, Spec::baseline_m, 0);
  const Eigen::Vector3d z_axis =
      (Eigen::Vector3d(0, 0, Spec::convergence_distance_m) - centre_camera).normalized();
  const Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
  g.R_projector_camera.row(0) = x_axis.transpose();
  g.R_projector_camera.row(1) = y_axis.transpose();
  g.R_projector_camera.row(2) = z_axis.transpose();
  g.t_projector_camera_m = -g.R_projector_camera * centre_camera;
  return g;
}

}  // namespace avs::decode
