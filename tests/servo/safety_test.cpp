// Every host-side safety rule, alone: each test fails when its rule is removed.
#include "avs/servo/safety.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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
const CommandFreshness freshness{timeout_s, 0.005};

TEST(Safety, PassesAFreshCommandInsideAllLimits) {
  const SafetyOutput out = apply_safety(config(), freshness, fresh(1.5));
  EXPECT_DOUBLE_EQ(out.torque_nm, 1.5);
  EXPECT_EQ(out.reasons, safety_none);
}

TEST(Safety, ClampsToTheConfiguredLimit) {
  const SafetyOutput out = apply_safety(config(), freshness, fresh(-4.0));
  EXPECT_DOUBLE_EQ(out.torque_nm, -2.0);
  EXPECT_TRUE(out.reasons & safety_torque_clamped);
}

TEST(Safety, ClampsToTheMotorLimitWhenTheConfiguredOneIsHigher) {
  AxisSafetyConfig c = config();
  c.configured_max_torque_nm = 50.0;
  EXPECT_DOUBLE_EQ(apply_safety(c, freshness, fresh(9.0)).torque_nm, 5.73);
}

TEST(Safety, StaleCommandGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.now_s = in.command_stamp_s + timeout_s + 1e-3;
  const SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_command_stale);
  in.now_s = in.command_stamp_s + timeout_s - 1e-3;
  EXPECT_DOUBLE_EQ(apply_safety(config(), freshness, in).torque_nm, 1.0);
}

TEST(Safety, MissingCommandGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.command_stamp_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(apply_safety(config(), freshness, in).torque_nm, 0.0);
}

TEST(Safety, EstopGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.estop = true;
  const SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_estop);
}

TEST(Safety, LinkFaultOrDisabledDriveGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.link_healthy = false;
  EXPECT_EQ(apply_safety(config(), freshness, in).torque_nm, 0.0);
  in = fresh(1.0);
  in.drive_enabled = false;
  EXPECT_EQ(apply_safety(config(), freshness, in).torque_nm, 0.0);
  in = fresh(1.0);
  in.feedback_valid = false;
  EXPECT_EQ(apply_safety(config(), freshness, in).torque_nm, 0.0);
}

TEST(Safety, NoTorquePushingPastASoftLimit) {
  SafetyInput in = fresh(1.0);
  in.q_rad = 1.05;  // past the upper limit, at rest
  SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_soft_limit_block);
  in.command_nm = -1.0;  // back inside is allowed
  EXPECT_DOUBLE_EQ(apply_safety(config(), freshness, in).torque_nm, -1.0);
  in = fresh(-1.0);
  in.q_rad = -1.2;
  EXPECT_EQ(apply_safety(config(), freshness, in).torque_nm, 0.0);
}

TEST(Safety, BrakesWhenMovingTowardANearbyLimit) {
  SafetyInput in = fresh(0.5);
  in.q_rad = 0.95;  // inside the 0.1 rad zone, slow enough to stay inside the envelope
  in.qd_rad_s = 2.0;
  SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_LT(out.torque_nm, 0.0);
  EXPECT_DOUBLE_EQ(out.torque_nm, -0.1);  // -gain * qd
  EXPECT_TRUE(out.reasons & safety_soft_limit_brake);
  EXPECT_FALSE(out.reasons & safety_soft_limit_envelope);
  in.qd_rad_s = -2.0;  // moving away: untouched
  EXPECT_DOUBLE_EQ(apply_safety(config(), freshness, in).torque_nm, 0.5);
  in = fresh(-0.5);
  in.q_rad = -0.95;
  in.qd_rad_s = -2.0;
  EXPECT_GT(apply_safety(config(), freshness, in).torque_nm, 0.0);
}

// Issue 20 1.1: stamps ahead of the arrival beyond the tolerance, and old arrivals.
TEST(Safety, FutureStampedCommandGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.command_stamp_s = in.now_s + 0.5;
  SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_command_future);
  in.command_stamp_s = in.now_s + 0.004;  // within the 5 ms tolerance
  EXPECT_DOUBLE_EQ(apply_safety(config(), freshness, in).torque_nm, 1.0);
  EXPECT_TRUE(is_future_stamped(freshness, 10.0 + 0.0051, 10.0));
  EXPECT_FALSE(is_future_stamped(freshness, 10.0 + 0.0049, 10.0));
  EXPECT_FALSE(is_future_stamped(freshness, 9.0, 10.0));
}

TEST(Safety, CommandIsStaleWhenItArrivedLongerAgoThanTheTimeout) {
  SafetyInput in = fresh(1.0);
  in.command_arrival_s = 10.0;
  in.command_stamp_s = 10.004;  // ahead, within the tolerance
  in.now_s = 10.0 + timeout_s + 1e-3;  // stamp age 17 ms, arrival age 21 ms
  SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_command_stale);
  in.now_s = 10.0 + timeout_s - 1e-3;
  EXPECT_DOUBLE_EQ(apply_safety(config(), freshness, in).torque_nm, 1.0);
}

TEST(Safety, LatchedFaultGivesZeroTorque) {
  SafetyInput in = fresh(1.0);
  in.fault_latched = true;
  const SafetyOutput out = apply_safety(config(), freshness, in);
  EXPECT_EQ(out.torque_nm, 0.0);
  EXPECT_TRUE(out.reasons & safety_fault_latched);
}

// Issue 20 1.4: the velocity envelope v_max(d) = sqrt(2 a_brake d).
double brake_rad_s2(const AxisSafetyConfig& c) {
  return c.envelope_brake_fraction * c.gear_efficiency * c.gear_ratio * c.configured_max_torque_nm /
         c.output_inertia_kg_m2;
}

TEST(Safety, EnvelopeBrakesAboveTheStoppingSpeedOnly) {
  const AxisSafetyConfig c = config();
  const double distance_rad = 0.5;
  const double v_max = std::sqrt(2 * brake_rad_s2(c) * distance_rad);
  SafetyInput in = fresh(1.5);
  in.q_rad = c.soft_upper_rad - distance_rad;  // outside the brake zone
  in.qd_rad_s = 0.95 * v_max;
  EXPECT_DOUBLE_EQ(apply_safety(c, freshness, in).torque_nm, 1.5);
  in.qd_rad_s = 1.05 * v_max;
  SafetyOutput out = apply_safety(c, freshness, in);
  EXPECT_DOUBLE_EQ(out.torque_nm, -2.0);  // braking torque instead of the command
  EXPECT_TRUE(out.reasons & safety_soft_limit_envelope);
  in.qd_rad_s = -1.05 * v_max;  // as fast, but away from the limit: untouched
  EXPECT_DOUBLE_EQ(apply_safety(c, freshness, in).torque_nm, 1.5);
  // The lower limit, mirrored.
  in = fresh(-1.5);
  in.q_rad = c.soft_lower_rad + distance_rad;
  in.qd_rad_s = -1.05 * v_max;
  EXPECT_DOUBLE_EQ(apply_safety(c, freshness, in).torque_nm, 2.0);
  in.qd_rad_s = -0.95 * v_max;
  EXPECT_DOUBLE_EQ(apply_safety(c, freshness, in).torque_nm, -1.5);
}

TEST(Safety, EnvelopeIsOffWithoutAnInertia) {
  AxisSafetyConfig c = config();
  c.output_inertia_kg_m2 = 0;
  SafetyInput in = fresh(1.5);
  in.q_rad = 0.5;
  in.qd_rad_s = 100.0;
  EXPECT_DOUBLE_EQ(apply_safety(c, freshness, in).torque_nm, 1.5);
}

// A frictionless axis (the worst case) driven by a saturated command through the safety
// rules with the drive client's timing: the feedback is one period old and the torque written
// then acts until the new one lands. It must never pass the limit, and get close to it.
TEST(Safety, EnvelopeStopsAFrictionlessAxisAtTheLimitDespiteTheLatency) {
  const AxisSafetyConfig c = config();
  const double accel_per_nm = c.gear_efficiency * c.gear_ratio / c.output_inertia_kg_m2;
  for (const double command_nm : {2.0, -2.0, 0.3, -0.3}) {
    for (const double period_s : {0.001, 0.002}) {
      double q = 0, v = 0;                 // the axis now
      double q_read = 0, v_read = 0;       // read one period ago
      double previous_nm = 0, extreme_rad = 0;
      double t = 10.0;
      for (int i = 0; i < 4000; ++i) {
        t += period_s;
        SafetyInput in;
        in.command_nm = command_nm;
        in.command_stamp_s = in.command_arrival_s = in.now_s = t;
        in.q_rad = q_read;
        in.qd_rad_s = v_read;
        in.previous_torque_nm = previous_nm;
        in.feedback_age_s = period_s;
        in.command_hold_s = period_s;
        const double tau = apply_safety(c, freshness, in).torque_nm;
        q_read = q;
        v_read = v;
        const double a = accel_per_nm * tau;
        q += v * period_s + 0.5 * a * period_s * period_s;
        v += a * period_s;
        previous_nm = tau;
        extreme_rad = command_nm > 0 ? std::max(extreme_rad, q) : std::min(extreme_rad, q);
      }
      const double limit = command_nm > 0 ? c.soft_upper_rad : c.soft_lower_rad;
      EXPECT_LE(std::abs(extreme_rad), std::abs(limit) + 1e-9)
          << command_nm << " N m at " << period_s << " s";
      EXPECT_GT(std::abs(extreme_rad), 0.95 * std::abs(limit))
          << command_nm << " N m at " << period_s << " s";
    }
  }
}

// Issue 20 1.2: the host-side fault latch.
TEST(FaultLatch, HoldsUntilAResetAndStableOperationEnabled) {
  FaultLatch latch(3);
  EXPECT_FALSE(latch.update(DriveState::operation_enabled, false));
  EXPECT_TRUE(latch.update(DriveState::fault_reaction_active, false));
  EXPECT_TRUE(latch.update(DriveState::fault, false));
  for (int i = 0; i < 10; ++i) {  // back without a reset: stays latched
    EXPECT_TRUE(latch.update(DriveState::operation_enabled, false));
  }
  EXPECT_TRUE(latch.update(DriveState::operation_enabled, true));  // reset seen: 1
  EXPECT_TRUE(latch.update(DriveState::operation_enabled, false));  // 2
  EXPECT_FALSE(latch.update(DriveState::operation_enabled, false));  // 3: cleared
}

TEST(FaultLatch, AFlickeringStatuswordRestartsTheCount) {
  FaultLatch latch(3);
  latch.update(DriveState::fault, true);
  latch.update(DriveState::switch_on_disabled, false);  // after the reset edge
  latch.update(DriveState::operation_enabled, false);
  latch.update(DriveState::operation_enabled, false);
  EXPECT_TRUE(latch.update(DriveState::switched_on, false));  // count restarts
  EXPECT_TRUE(latch.update(DriveState::operation_enabled, false));
  EXPECT_TRUE(latch.update(DriveState::operation_enabled, false));
  EXPECT_FALSE(latch.update(DriveState::operation_enabled, false));
}

TEST(FaultLatch, AFaultAfterTheResetNeedsANewReset) {
  FaultLatch latch(2);
  latch.update(DriveState::fault, true);
  latch.update(DriveState::switch_on_disabled, false);
  latch.update(DriveState::fault, false);  // the fault comes back, no request pending
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(latch.update(DriveState::operation_enabled, false));
}

TEST(Safety, DescribesReasons) {
  EXPECT_EQ(describe_safety_reasons(safety_estop | safety_command_stale), "e-stop, command stale");
  EXPECT_EQ(describe_safety_reasons(safety_none), "none");
}

}  // namespace
}  // namespace avs::servo
