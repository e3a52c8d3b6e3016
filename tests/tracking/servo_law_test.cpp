#include "avs/tracking/servo_law.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace avs::tracking {
namespace {

ServoLawConfig config(JacobianForm form) {
  ServoLawConfig c;
  c.jacobian = form;
  c.fx_px = 800;
  c.fy_px = 810;
  c.a_m = 0.05;
  c.max_torque_nm = {100, 100};  // no saturation unless a test asks for it
  return c;
}

TEST(ImageJacobian, SimplifiedIsDiagMinusFCosQ2MinusF) {
  const Eigen::Matrix2d j = image_jacobian(JacobianForm::simplified,
                                           config(JacobianForm::simplified), {10, 20}, 1.0, 0.3);
  EXPECT_DOUBLE_EQ(j(0, 0), -800 * std::cos(0.3));
  EXPECT_DOUBLE_EQ(j(1, 1), -810);
  EXPECT_EQ(j(0, 1), 0);
  EXPECT_EQ(j(1, 0), 0);
}

TEST(ImageJacobian, FullFormMatchesEq15) {
  const ServoLawConfig c = config(JacobianForm::full);
  const double x_c = 1.2, q2 = 0.4;
  const Eigen::Vector2d m_g(40, -30);
  const double z_c = -m_g.x() * x_c / c.fx_px;  // Eq. 10
  const double y_c = m_g.y() * x_c / c.fy_px;
  const Eigen::Matrix2d j = image_jacobian(JacobianForm::full, c, m_g, x_c, q2);
  EXPECT_NEAR(j(0, 0), -c.fx_px / x_c * ((c.a_m + x_c) * std::cos(q2) + y_c * std::sin(q2)), 1e-9);
  EXPECT_EQ(j(0, 1), 0);
  EXPECT_NEAR(j(1, 0), -c.fy_px * z_c / x_c * std::sin(q2), 1e-9);
  EXPECT_NEAR(j(1, 1), -c.fy_px / x_c * (c.a_m + x_c), 1e-9);
}

TEST(ImageJacobian, FullFormTendsToTheSimplifiedOneWhenASmallAndTargetCentred) {
  ServoLawConfig c = config(JacobianForm::full);
  c.a_m = 0;
  const Eigen::Matrix2d full = image_jacobian(JacobianForm::full, c, {0, 0}, 2.0, 0.2);
  const Eigen::Matrix2d simple = image_jacobian(JacobianForm::simplified, c, {0, 0}, 2.0, 0.2);
  EXPECT_TRUE(full.isApprox(simple, 1e-12)) << full << "\n" << simple;
}

// Image-plane geometry check: J predicts how the centroid moves when the head turns. For a
// pure pan (q2 = 0) a target at angle theta appears at x = f tan(theta - q1); dx/dq1 = -f at
// the centre: the sign of J11.
TEST(ImageJacobian, SignMatchesTheProjection) {
  const double f = 800, theta = 0.0, dq = 1e-6;
  const double dx_dq1 = (f * std::tan(theta - dq) - f * std::tan(theta)) / dq;
  const Eigen::Matrix2d j =
      image_jacobian(JacobianForm::simplified, config(JacobianForm::simplified), {0, 0}, 1, 0);
  EXPECT_NEAR(j(0, 0), dx_dq1, 1e-3);
}

TEST(ServoLaw, TargetRightOfCentreGivesPanTorqueTowardIt) {
  for (JacobianForm form : {JacobianForm::simplified, JacobianForm::full}) {
    ServoLawInput in;
    in.m_g_px = {50, 0};  // right of centre
    in.mean_depth_m = 1.0;
    const ServoLawResult r = servo_law(config(form), in);
    EXPECT_GT(r.torque_nm.x(), 0.0);  // positive pan turns toward +x
    EXPECT_NEAR(r.torque_nm.y(), 0.0, 1e-12);
    in.m_g_px = {-50, 0};
    EXPECT_LT(servo_law(config(form), in).torque_nm.x(), 0.0);
    in.m_g_px = {0, 40};  // below centre: positive tilt
    EXPECT_GT(servo_law(config(form), in).torque_nm.y(), 0.0);
  }
}

TEST(ServoLaw, Eq16ValuesAndVelocityDamping) {
  ServoLawConfig c = config(JacobianForm::simplified);
  c.kp_nm_per_rad = {2.0, 0.5};
  c.kv_nm_s_per_rad = {0.1, 0.02};
  ServoLawInput in;
  in.m_g_px = {80, -81};
  in.qd_rad_s = {3.0, -2.0};
  const ServoLawResult r = servo_law(c, in);
  EXPECT_NEAR(r.torque_nm.x(), 2.0 * (-80.0 / -800.0) - 0.1 * 3.0, 1e-12);
  EXPECT_NEAR(r.torque_nm.y(), 0.5 * (81.0 / -810.0) + 0.02 * 2.0, 1e-12);
  EXPECT_EQ(r.error_px, Eigen::Vector2d(-80, 81));
}

TEST(ServoLaw, TorqueLimitsAndFallbackWithoutDepth) {
  ServoLawConfig c = config(JacobianForm::full);
  c.max_torque_nm = {5.73, 0.9555};
  c.kp_nm_per_rad = {1000, 1000};
  ServoLawInput in;
  in.m_g_px = {300, -300};
  in.mean_depth_m = std::nan("");
  const ServoLawResult r = servo_law(c, in);
  EXPECT_TRUE(r.saturated);
  EXPECT_DOUBLE_EQ(r.torque_nm.x(), 5.73);
  EXPECT_DOUBLE_EQ(r.torque_nm.y(), -0.9555);
  EXPECT_EQ(r.form_used, JacobianForm::simplified);
}

TEST(ServoLaw, StaysInvertibleNearTiltNinetyDegrees) {
  ServoLawInput in;
  in.m_g_px = {10, 0};
  in.q_rad = {0, M_PI / 2};
  const ServoLawResult r = servo_law(config(JacobianForm::simplified), in);
  EXPECT_TRUE(std::isfinite(r.torque_nm.x()));
}

}  // namespace
}  // namespace avs::tracking
