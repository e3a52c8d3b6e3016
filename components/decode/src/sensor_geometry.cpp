#include "avs/decode/sensor_geometry.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace avs::decode {

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
