#include "avs/servo/simulated_drive.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

void write_one(SimulatedDrive& drive, Signal s, std::int64_t counts) {
  const RegisterSpec& spec = drive.registers()[s];
  std::vector<std::uint16_t> regs(spec.width_registers);
  write_counts(spec, counts, regs);
  drive.apply_write(spec.address, regs);
}

void enable(SimulatedDrive& drive) {
  drive.step(0.001);
  write_one(drive, Signal::mode_of_operation, mode_cyclic_synchronous_torque);
  for (auto cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
    write_one(drive, Signal::controlword, cw);
  }
}

TEST(SimulatedDrive, AppliesTheQuantisedTorqueOnlyWhenEnabledInATorqueMode) {
  SimulatedDrive drive(pan_drive_config());
  const RegisterSpec& torque = drive.registers()[Signal::target_torque];
  drive.step(0.001);
  write_one(drive, Signal::target_torque, to_counts(torque, 1.0));
  drive.step(0.001);
  EXPECT_EQ(drive.applied_torque_nm(), 0.0);  // not enabled
  enable(drive);
  write_one(drive, Signal::target_torque, to_counts(torque, 1.0));
  drive.step(0.001);
  EXPECT_NEAR(drive.applied_torque_nm(), 1.0, torque.scale / 2);
  EXPECT_GT(drive.plant().state().qd_rad_s, 0.0);
}

TEST(SimulatedDrive, WatchdogRemovesTorqueWhenCommandsStop) {
  SimulatedDriveConfig config = pan_drive_config();
  config.watchdog_timeout_s = 0.002;
  SimulatedDrive drive(config);
  enable(drive);
  write_one(drive, Signal::target_torque, 500);
  drive.step(0.001);
  EXPECT_GT(drive.applied_torque_nm(), 0.0);
  drive.step(0.001);  // 2 ms without a command: trips
  EXPECT_EQ(drive.applied_torque_nm(), 0.0);
  drive.step(0.001);
  EXPECT_EQ(drive.state_machine().state(), DriveState::fault);
  EXPECT_EQ(drive.state_machine().error_code(), error_code_watchdog);
}

TEST(SimulatedDrive, WatchdogCanBeDisabled) {
  SimulatedDriveConfig config = pan_drive_config();
  config.watchdog_timeout_s = 0;
  SimulatedDrive drive(config);
  enable(drive);
  write_one(drive, Signal::target_torque, 500);
  for (int i = 0; i < 100; ++i) drive.step(0.001);
  EXPECT_GT(drive.applied_torque_nm(), 0.0);
}

TEST(SimulatedDrive, QuickStopBrakesToStandstillThenDisables) {
  SimulatedDriveConfig config = pan_drive_config();
  config.watchdog_timeout_s = 0;
  SimulatedDrive drive(config);
  enable(drive);
  write_one(drive, Signal::target_torque, 1000);
  for (int i = 0; i < 20; ++i) drive.step(0.001);
  ASSERT_GT(drive.plant().state().qd_rad_s, 1.0);
  write_one(drive, Signal::controlword, controlword::quick_stop);
  drive.step(0.001);
  EXPECT_LT(drive.applied_torque_nm(), 0.0);  // braking
  for (int i = 0; i < 2000 && drive.state_machine().state() == DriveState::quick_stop_active; ++i) {
    drive.step(0.001);
  }
  EXPECT_EQ(drive.state_machine().state(), DriveState::switch_on_disabled);
  EXPECT_LT(std::abs(drive.plant().state().qd_rad_s), 0.01);
}

TEST(SimulatedDrive, RegistersCarryStateEchoAndProbe) {
  SimulatedDrive drive(pan_drive_config());
  enable(drive);
  write_one(drive, Signal::host_counter, 1234);
  std::vector<std::uint16_t> bank(drive.registers().register_count());
  drive.fill_registers(bank);
  const RegisterMap& m = drive.registers();
  EXPECT_EQ(decode_statusword(bank[m[Signal::statusword].address]), DriveState::operation_enabled);
  EXPECT_EQ(bank[m[Signal::echo_counter].address], 1234);
  EXPECT_EQ(read_counts(m[Signal::word_order_probe],
                        std::span(bank).subspan(m[Signal::word_order_probe].address, 2)),
            word_order_probe_value);
  EXPECT_FALSE(drive.accepts_write(m[Signal::statusword].address, 1));
  EXPECT_TRUE(drive.accepts_write(0, 3));
}

TEST(SimulatedDrive, UnsupportedModeIsNotTakenAndGivesNoTorque) {
  SimulatedDriveConfig config = pan_drive_config();
  config.watchdog_timeout_s = 0;
  SimulatedDrive drive(config);
  drive.step(0.001);
  write_one(drive, Signal::mode_of_operation, 1);  // profile position: not simulated
  for (auto cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
    write_one(drive, Signal::controlword, cw);
  }
  write_one(drive, Signal::target_torque, 500);
  drive.step(0.001);
  EXPECT_EQ(drive.mode_display(), 0);
  EXPECT_EQ(drive.applied_torque_nm(), 0.0);
}

}  // namespace
}  // namespace avs::servo
