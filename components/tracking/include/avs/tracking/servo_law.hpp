// Visual servo law (paper section 5.2): tau = Kp J^-1 (m_d - m_g) - Kv q'  (Eq. 16) with the
// image Jacobian of Eq. 15, full or simplified. Conventions (docs/servo.md):
//   * m_g in pixels relative to the principal point, x right, y down (image u, v);
//   * the paper's camera frame: X_c along the optical axis, Y_c along image y, Z_c along -x
//     (Eq. 10: m_g = [-f Z_c / X_c, f Y_c / X_c]);
//   * q = [q1 pan, q2 tilt]; positive pan turns the optical axis toward image +x and positive
//     tilt toward image +y, which is what dm_g/dq = J with J11 = -f cos q2, J22 = -f means;
//   * the output is the motor torque command of each axis (N m), limited per axis.
#pragma once

#include <Eigen/Core>

namespace avs::tracking {

enum class JacobianForm {
  full,        ///< Eq. 15, left: uses X_c, Y_c, Z_c, a and q2
  simplified,  ///< Eq. 15, right: diag(-f cos q2, -f)
};

struct ServoLawConfig {
  JacobianForm jacobian = JacobianForm::simplified;
  double fx_px = 0;  ///< focal length f in pixels along x (row 1 of J)
  double fy_px = 0;  ///< along y (row 2 of J)
  double a_m = 0.0;  ///< Figure 3: offset from the tilt axis to the camera centre along X_c
  /// K_p, K_v (pan, tilt): tuned on servo_tracking_loop.yaml, what every experiment uses.
  Eigen::Vector2d kp_nm_per_rad = {12.0, 2.0};
  Eigen::Vector2d kv_nm_s_per_rad = {0.3, 0.05};
  Eigen::Vector2d m_d_px = Eigen::Vector2d::Zero();  ///< desired image position, usually 0
  Eigen::Vector2d max_torque_nm = {5.73, 0.9555};    ///< Table 3 motor limits
  double min_cos_q2 = 0.1;                           ///< keeps J invertible near tilt = +-90 deg
};

struct ServoLawInput {
  Eigen::Vector2d m_g_px = Eigen::Vector2d::Zero();  ///< Eq. 9 centroid
  double mean_depth_m = 0;  ///< X_c; <= 0 or NaN: the full form falls back to the simplified
  Eigen::Vector2d q_rad = Eigen::Vector2d::Zero();
  Eigen::Vector2d qd_rad_s = Eigen::Vector2d::Zero();
};

struct ServoLawResult {
  Eigen::Vector2d torque_nm = Eigen::Vector2d::Zero();  ///< after the limits
  Eigen::Vector2d error_px = Eigen::Vector2d::Zero();   ///< m_d - m_g
  Eigen::Matrix2d jacobian = Eigen::Matrix2d::Zero();   ///< the J that was inverted
  JacobianForm form_used = JacobianForm::simplified;
  bool saturated = false;
};

/// Eq. 15. Y_c and Z_c come from m_g and X_c through Eq. 10.
Eigen::Matrix2d image_jacobian(JacobianForm form, const ServoLawConfig& config,
                               const Eigen::Vector2d& m_g_px, double mean_depth_m, double q2_rad);

/// Eq. 16.
ServoLawResult servo_law(const ServoLawConfig& config, const ServoLawInput& input);

}  // namespace avs::tracking
