#include "avs/tracking/servo_law.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace avs::tracking {
namespace {

double guarded_cos(double q2, double min_cos) {
  const double c = std::cos(q2);
  if (std::abs(c) >= min_cos) return c;
  return c >= 0 ? min_cos : -min_cos;
}

}  // namespace

Eigen::Matrix2d image_jacobian(JacobianForm form, const ServoLawConfig& config,
                               const Eigen::Vector2d& m_g, double x_c, double q2) {
  const double fx = config.fx_px;
  const double fy = config.fy_px;
  Eigen::Matrix2d j = Eigen::Matrix2d::Zero();
  if (form == JacobianForm::simplified) {
    j(0, 0) = -fx * guarded_cos(q2, config.min_cos_q2);
    j(1, 1) = -fy;
    return j;
  }
  // Eq. 10 inverted: Z_c = -x X_c / f, Y_c = y X_c / f.
  const double z_c = -m_g.x() * x_c / fx;
  const double y_c = m_g.y() * x_c / fy;
  const double a = config.a_m;
  j(0, 0) = -fx / x_c * ((a + x_c) * guarded_cos(q2, config.min_cos_q2) + y_c * std::sin(q2));
  j(1, 0) = -fy * z_c / x_c * std::sin(q2);
  j(1, 1) = -fy / x_c * (a + x_c);
  return j;
}

ServoLawResult servo_law(const ServoLawConfig& config, const ServoLawInput& in) {
  ServoLawResult out;
  out.form_used = config.jacobian;
  if (config.jacobian == JacobianForm::full && !(in.mean_depth_m > 0)) {
    out.form_used = JacobianForm::simplified;  // no usable X_c
  }
  out.jacobian = image_jacobian(out.form_used, config, in.m_g_px, in.mean_depth_m, in.q_rad.y());
  out.error_px = config.m_d_px - in.m_g_px;
  // J is lower triangular with non-zero diagonal (guarded), so it is invertible.
  const Eigen::Vector2d joint_error_rad = out.jacobian.inverse() * out.error_px;
  const Eigen::Vector2d tau = config.kp_nm_per_rad.cwiseProduct(joint_error_rad) -
                              config.kv_nm_s_per_rad.cwiseProduct(in.qd_rad_s);  // Eq. 16
  for (int i = 0; i < 2; ++i) {
    const double limit = config.max_torque_nm[i];
    out.torque_nm[i] = std::clamp(tau[i], -limit, limit);
    out.saturated = out.saturated || std::abs(tau[i]) > limit;
  }
  return out;
}

}  // namespace avs::tracking
