// The simulated amplifier through a REAL libmodbus client on loopback: CiA 402 transitions,
// the watchdog, quick stop, fault reset, exceptions. The server runs on the external clock,
// so drive time only moves when the test steps it.
#include "avs/servo/amplifier_server.hpp"

#include <cerrno>

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

class AmplifierServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    AmplifierServerConfig config;  // port 0: a free port
    config.axes = {pan_drive_config(1), tilt_drive_config(2)};
    config.axes[0].watchdog_timeout_s = 0.002;
    server_ = std::make_unique<AmplifierServer>(config);
    server_->step(0.001);  // power-up: Not ready -> Switch on disabled
    ctx_ = make_tcp_context("127.0.0.1", server_->port());
    set_response_timeout(ctx_.get(), 1.0);
    check_modbus(modbus_connect(ctx_.get()), "connect");
    modbus_set_slave(ctx_.get(), 1);
  }

  std::uint16_t read(std::uint16_t address) {
    std::uint16_t value = 0;
    check_modbus(modbus_read_registers(ctx_.get(), address, 1, &value), "read");
    return value;
  }
  void write(std::uint16_t address, std::uint16_t value) {
    check_modbus(modbus_write_register(ctx_.get(), address, value), "write");
  }
  DriveState state() { return decode_statusword(read(4)); }
  void enable() {
    write(3, mode_cyclic_synchronous_torque);
    write(0, controlword::shutdown);
    ASSERT_EQ(state(), DriveState::ready_to_switch_on);
    write(0, controlword::switch_on);
    ASSERT_EQ(state(), DriveState::switched_on);
    write(0, controlword::enable_operation);
    ASSERT_EQ(state(), DriveState::operation_enabled);
  }

  std::unique_ptr<AmplifierServer> server_;
  ModbusContext ctx_;
};

TEST_F(AmplifierServerTest, EnableSequenceAndTorqueThroughTheRegisterMap) {
  EXPECT_EQ(state(), DriveState::switch_on_disabled);
  enable();
  EXPECT_EQ(static_cast<std::int16_t>(read(5)), mode_cyclic_synchronous_torque);
  write(1, 500);  // 50 % of rated torque
  server_->step(0.001);
  double applied = 0;
  server_->with_drive(0, [&](SimulatedDrive& d) { applied = d.applied_torque_nm(); });
  EXPECT_NEAR(applied, 0.5 * pan_rated_torque_nm, 1e-9);
  EXPECT_EQ(static_cast<std::int16_t>(read(6)), 500);  // torque actual
  // position and velocity in the 32-bit registers, high word first
  std::uint16_t regs[4];
  check_modbus(modbus_read_registers(ctx_.get(), 8, 4, regs), "read actuals");
  EXPECT_GT(read_counts({true, 10, 2, true, WordOrder::high_first, 1}, {regs + 2, 2}), 0);
}

TEST_F(AmplifierServerTest, UnitsAreIndependentAxes) {
  enable();
  modbus_set_slave(ctx_.get(), 2);
  EXPECT_EQ(state(), DriveState::switch_on_disabled);
  modbus_set_slave(ctx_.get(), 7);  // no such axis
  std::uint16_t value;
  EXPECT_EQ(modbus_read_registers(ctx_.get(), 4, 1, &value), -1);
  EXPECT_EQ(errno, EMBXGTAR);
}

TEST_F(AmplifierServerTest, WatchdogFaultsWhenCommandsStopAndResetRecovers) {
  enable();
  write(1, 500);
  server_->step(0.001);
  EXPECT_EQ(state(), DriveState::operation_enabled);
  server_->step(0.001);  // 2 ms without a command
  double applied = 1;
  server_->with_drive(0, [&](SimulatedDrive& d) { applied = d.applied_torque_nm(); });
  EXPECT_EQ(applied, 0.0);
  server_->step(0.001);
  EXPECT_EQ(state(), DriveState::fault);
  EXPECT_EQ(read(7), error_code_watchdog);
  write(0, 0);
  write(0, controlword::fault_reset_bit);
  EXPECT_EQ(state(), DriveState::switch_on_disabled);
  EXPECT_EQ(read(7), 0);
}

TEST_F(AmplifierServerTest, QuickStopAndInjectedFault) {
  enable();
  write(0, controlword::quick_stop);
  EXPECT_EQ(state(), DriveState::quick_stop_active);
  server_->step(0.001);  // at rest: quick stop finishes
  EXPECT_EQ(state(), DriveState::switch_on_disabled);
  enable();
  server_->raise_drive_fault(0, error_code_injected);
  server_->step(0.001);
  EXPECT_EQ(state(), DriveState::fault);
  EXPECT_EQ(read(7), error_code_injected);
}

TEST_F(AmplifierServerTest, ReadOnlyAndOutOfMapWritesAreExceptions) {
  EXPECT_EQ(modbus_write_register(ctx_.get(), 4, 0x27), -1);  // statusword
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_register(ctx_.get(), 200, 1), -1);
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(state(), DriveState::switch_on_disabled);
}

TEST_F(AmplifierServerTest, SilentServerTimesOutAndDroppedConnectionIsReported) {
  set_response_timeout(ctx_.get(), 0.05);
  server_->set_silent(true);
  std::uint16_t value;
  EXPECT_EQ(modbus_read_registers(ctx_.get(), 4, 1, &value), -1);
  EXPECT_EQ(errno, ETIMEDOUT);
  server_->set_silent(false);
  // After a timeout libmodbus TCP is only trusted on a fresh connection (reference 1.4).
  modbus_close(ctx_.get());
  check_modbus(modbus_connect(ctx_.get()), "reconnect");
  EXPECT_EQ(state(), DriveState::switch_on_disabled);
  server_->drop_connections();
  int rc = 0;
  for (int i = 0; i < 50 && rc != -1; ++i) rc = modbus_read_registers(ctx_.get(), 4, 1, &value);
  EXPECT_EQ(rc, -1);
}

}  // namespace
}  // namespace avs::servo
