// Sensor geometry shared by the decoder and the simulator: camera and projector lens models
// (geometry::CameraModel, the project's one camera type), the projector's pose
// relative to the camera, the code layout, and the 3x4 matrices C and P of Eq. 4.
#pragma once

#include <Eigen/Core>

#include "avs/decode/gray_code.hpp"
#include "avs/geometry/camera_model.hpp"

namespace avs::decode {

/// Everything the decoder needs to turn a code into depth. Frames: the camera frame is the
/// reference (x right, y down, z forward); p_projector = R_projector_camera * p_camera +
/// t_projector_camera_m (the OpenCV stereoCalibrate convention).
struct SensorGeometry {
  geometry::CameraModel camera;
  geometry::CameraModel projector;
  Eigen::Matrix3d R_projector_camera = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_projector_camera_m = Eigen::Vector3d::Zero();
  CodeLayout layout;

  /// Eq. 4: C = K_c [I | 0] (camera at the origin of the reference frame).
  Eigen::Matrix<double, 3, 4> camera_matrix() const;
  /// Eq. 4: P = K_p [R | t].
  Eigen::Matrix<double, 3, 4> projector_matrix() const;
  /// Projector optical centre in the camera frame, -R^T t.
  Eigen::Vector3d projector_centre_camera_m() const;
  /// Continuous projector row at the centre of `code` (rows_per_code = 4: rows 4c..4c+3, centre
  /// 4c + 1.5, plus first_row).
  double code_centre_row(int code) const;
};

/// Numbers behind default_sensor_geometry(), from the paper (Tables 1-2, sections 4 and 4.3).
struct DefaultGeometrySpec {
  // Camera (Table 2): 512 x 512, 6 mm lens. The 57.4 x 44.3 deg FOV of Table 2 is the lens on a
  // full 1/1.8" (4:3) sensor; a square 512 x 512 sensor cannot show both. We assume square
  // pixels and let the 512 rows span the 44.3 deg vertical FOV: f = 256 / tan(22.15 deg) =
  // 628.8 px, i.e. a pixel pitch of 6 mm / 628.8 = 9.54 um (close to the 10 um of Photron's
  // 512 x 512 sensors). Both axes then see 44.3 deg.
  static constexpr int camera_width = 512;
  static constexpr int camera_height = 512;
  static constexpr double camera_focal_length_m = 6e-3;
  static constexpr double camera_vertical_fov_deg = 44.3;
  // Projector (Table 1): 912 x 1140 pattern-mode resolution, throw ratio D/W = 1.2 over its 912
  // columns -> f = 1.2 * 912 = 1094.4 px, square pixels assumed; 1060 of the 1140 rows carry
  // the 265 codes (4 rows each), centred: first_row = 40.
  static constexpr int projector_width = 912;
  static constexpr int projector_height = 1140;
  static constexpr double projector_throw_ratio = 1.2;
  // Baseline (section 4.3): t = 0.2 m along the coded direction (camera y; the projector sits
  // below the camera), optical axes converging at 1.0 m on the camera axis.
  static constexpr double baseline_m = 0.2;
  static constexpr double convergence_distance_m = 1.0;
};

/// The paper's sensor as described by DefaultGeometrySpec, no lens distortion.
SensorGeometry default_sensor_geometry();

}  // namespace avs::decode
