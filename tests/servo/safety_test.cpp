// Every host-side safety rule, alone: each test fails when its rule is removed.
#include "avs/servo/safety.hpp"

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

AxisSafetyConfig config() {
  AxisSafetyConfig c;
  c.configured_max_torque_nm = 2.0;
  c.motor_max_torque_nm = 5.73;
  c.soft_lower_rad = -1.0;
  c.soft_upper_rad = 1.0;
  c.brake_zone_rad = 0.1;
  c.brake_gain_nm_s_per_rad = 0.05;
  return c;
}

SafetyInput fresh(double command_nm) {
  SafetyInput in;
  in.command_nm = command_nm;
  in.command_stamp_s = 10.0;
  in.now_s = 10.001;
  return in;
}

constexpr double timeout_s = 0.02;

TEST(Safety, PassesAFreshCommandInsideAllLimits) {
  const SafetyOutput out = apply_safety(config(), timeout_s, fresh(1.5));
  EXPECT_DOUBLE_EQ(out.torque_nm, 1.5);
  EXPECT_EQ(out.reasons, safety_none);
}

TEST(Safety, ClampsToTheConfiguredLimit) {
  const SafetyOutput out = apply_safety(config(), timeout_s, fresh(-4.0));
  EXPECT_DOUBLE_EQ(out.torque_nm, -2.0);
  EXPECT_TRUE(out.reasons & safety_torque_clamped);
}

TEST(Safety, ClampsToTheMotorLimitWhenTheConfiguredOneIsHigher) {
  AxisSafetyConfig c = config();
  c.configured_max_torque_nm = 50.0;
  EXPECT_DOUBLE_EQ(apply_safety(c, timeout_s, fresh(9.0)).torque_nm, 5.73);
}

TEST(Safety, StaleCommandGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.now_s = in.command_stamp_s + timeout_s + 1e-3;
  const SafetyOutput out = apply_safety(config(), timeout_s, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_command_stale);
  in.now_s = in.command_stamp_s + timeout_s - 1e-3;
  EXPECT_DOUBLE_EQ(apply_safety(config(), timeout_s, in).torque_nm, 1.0);
}

TEST(Safety, MissingCommandGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.command_stamp_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(apply_safety(config(), timeout_s, in).torque_nm, 0.0);
}

TEST(Safety, EstopGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.estop = true;
  const SafetyOutput out = apply_safety(config(), timeout_s, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_estop);
}

TEST(Safety, LinkFaultOrDisabledDriveGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.link_healthy = false;
  EXPECT_EQ(apply_safety(config(), timeout_s, in).torque_nm, 0.0);
  in = fresh(1.0);
  in.drive_enabled = false;
  EXPECT_EQ(apply_safety(config(), timeout_s, in).torque_nm, 0.0);
  in = fresh(1.0);
  in.feedback_valid = false;
  EXPECT_EQ(apply_safety(config(), timeout_s, in).torque_nm, 0.0);
}

TEST(Safety, NoTorquePushingPastASoftLimit) {
  SafetyInput in = fresh(1.0);
  in.q_rad = 1.05;  // past the upper limit, at rest
  SafetyOutput out = apply_safety(config(), timeout_s, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_soft_limit_block);
  in.command_nm = -1.0;  // back inside is allowed
  EXPECT_DOUBLE_EQ(apply_safety(config(), timeout_s, in).torque_nm, -1.0);
  in = fresh(-1.0);
  in.q_rad = -1.2;
  EXPECT_EQ(apply_safety(config(), timeout_s, in).torque_nm, 0.0);
}

TEST(Safety, BrakesWhenMovingTowardANearbyLimit) {
  SafetyInput in = fresh(0.5);
  in.q_rad = 0.95;  // inside the 0.1 rad zone
  in.qd_rad_s = 10.0;
  SafetyOutput out = apply_safety(config(), timeout_s, in);
  EXPECT_LT(out.torque_nm, 0.0);
  EXPECT_DOUBLE_EQ(out.torque_nm, -0.5);  // -gain * qd
  EXPECT_TRUE(out.reasons & safety_soft_limit_brake);
  in.qd_rad_s = -10.0;  // moving away: untouched
  EXPECT_DOUBLE_EQ(apply_safety(config(), timeout_s, in).torque_nm, 0.5);
  in = fresh(-0.5);
  in.q_rad = -0.95;
  in.qd_rad_s = -10.0;
  EXPECT_GT(apply_safety(config(), timeout_s, in).torque_nm, 0.0);
}

TEST(Safety, DescribesReasons) {
  EXPECT_EQ(describe_safety_reasons(safety_estop | safety_command_stale), "e-stop, command stale");
  EXPECT_EQ(describe_safety_reasons(safety_none), "none");
}

}  // namespace
}  // namespace avs::servo
