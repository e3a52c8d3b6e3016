#include "avs/servo/plant.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

// Issue 3 item 6: a torque step gives the acceleration eta N tau / J within 1 %.
TEST(AxisPlant, TorqueStepGivesEtaNTauOverJ) {
  for (AxisPlantConfig config : {pan_plant_config(), tilt_plant_config()}) {
    config.viscous_nm_s_per_rad = 0;
    config.coulomb_nm = 0;
    AxisPlant plant(config);
    const double tau = 0.5 * config.max_motor_torque_nm;
    const double dt = 0.001;
    plant.step(dt, tau);
    const double qd0 = plant.state().qd_rad_s;
    plant.step(0.01, tau);
    const double measured = (plant.state().qd_rad_s - qd0) / 0.01;
    const double expected = config.efficiency * config.gear_ratio * tau / config.inertia_kgm2;
    EXPECT_NEAR(measured, expected, 0.01 * expected);
    EXPECT_NEAR(plant.state().qdd_rad_s2, expected, 0.01 * expected);
  }
}

TEST(AxisPlant, FrictionReducesTheStepAccelerationAsModelled) {
  const AxisPlantConfig config = pan_plant_config();
  AxisPlant plant(config);
  const double tau = 2.0;
  plant.step(1e-4, tau);  // one sub-step from rest: q' ~ 0
  const double expected =
      (config.efficiency * config.gear_ratio * tau - config.coulomb_nm) / config.inertia_kgm2;
  EXPECT_NEAR(plant.state().qdd_rad_s2, expected, 0.01 * expected);
}

TEST(AxisPlant, StictionHoldsBelowCoulombFriction) {
  const AxisPlantConfig config = pan_plant_config();
  AxisPlant plant(config);
  const double tau = 0.9 * config.coulomb_nm / (config.efficiency * config.gear_ratio);
  plant.step(0.1, tau);
  EXPECT_EQ(plant.state().qd_rad_s, 0.0);
  EXPECT_EQ(plant.state().q_rad, 0.0);
}

TEST(AxisPlant, TorqueAndSpeedLimitsOfTable3) {
  const AxisPlantConfig config = pan_plant_config();
  AxisPlant plant(config);
  plant.step(0.001, 100.0);
  EXPECT_DOUBLE_EQ(plant.state().motor_torque_nm, 5.73);
  plant.step(1.0, 100.0);
  const double v_max = 6000.0 * 2 * M_PI / 60.0 / 4.2;  // 149.6 rad/s at the output
  EXPECT_NEAR(plant.max_output_speed_rad_s(), v_max, 1e-9);
  EXPECT_LE(plant.state().qd_rad_s, v_max + 1e-9);
  EXPECT_NEAR(plant.state().qd_rad_s, v_max, 1e-6);
}

TEST(AxisPlant, EncoderQuantisesAndWraps) {
  AxisPlant plant(pan_plant_config());
  const double count = plant.output_rad_per_count();
  plant.reset(10.4 * count);
  EXPECT_EQ(plant.position_counts(), 10);
  plant.reset(-0.5 * count);
  EXPECT_EQ(plant.position_counts(), -1);
  plant.reset((2147483647.0 + 2.5) * count);  // past INT32 max: wraps
  EXPECT_LT(plant.position_counts(), 0);
}

}  // namespace
}  // namespace avs::servo
