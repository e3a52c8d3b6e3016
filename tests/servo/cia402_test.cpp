#include "avs/servo/cia402.hpp"

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

Cia402StateMachine powered_up(QuickStopOption option = QuickStopOption::ramp_then_disable) {
  Cia402StateMachine sm(option);
  sm.step(true);  // Not ready -> Switch on disabled
  return sm;
}

TEST(Cia402, PowerUpThenEnableSequenceGatedOnEachStep) {
  Cia402StateMachine sm;
  EXPECT_EQ(sm.state(), DriveState::not_ready_to_switch_on);
  EXPECT_EQ(decode_statusword(sm.statusword()), DriveState::not_ready_to_switch_on);
  sm.step(true);
  EXPECT_EQ(sm.state(), DriveState::switch_on_disabled);
  sm.apply_controlword(controlword::enable_operation);  // must not skip Shutdown
  EXPECT_EQ(sm.state(), DriveState::switch_on_disabled);
  sm.apply_controlword(controlword::shutdown);
  EXPECT_EQ(sm.state(), DriveState::ready_to_switch_on);
  EXPECT_EQ(sm.statusword() & 0x6F, 0x21);
  sm.apply_controlword(controlword::switch_on);
  EXPECT_EQ(sm.state(), DriveState::switched_on);
  EXPECT_EQ(sm.statusword() & 0x6F, 0x23);
  EXPECT_FALSE(sm.torque_enabled());
  sm.apply_controlword(controlword::enable_operation);
  EXPECT_EQ(sm.state(), DriveState::operation_enabled);
  EXPECT_EQ(sm.statusword() & 0x6F, 0x27);
  EXPECT_TRUE(sm.torque_enabled());
}

TEST(Cia402, DisableOperationShutdownAndDisableVoltage) {
  Cia402StateMachine sm = powered_up();
  for (auto cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
    sm.apply_controlword(cw);
  }
  sm.apply_controlword(controlword::switch_on);  // disable operation
  EXPECT_EQ(sm.state(), DriveState::switched_on);
  sm.apply_controlword(controlword::enable_operation);
  sm.apply_controlword(controlword::shutdown);
  EXPECT_EQ(sm.state(), DriveState::ready_to_switch_on);
  sm.apply_controlword(controlword::switch_on);
  sm.apply_controlword(controlword::enable_operation);
  sm.apply_controlword(controlword::disable_voltage);
  EXPECT_EQ(sm.state(), DriveState::switch_on_disabled);
}

TEST(Cia402, QuickStopRampsThenDisablesOrHolds) {
  for (auto option : {QuickStopOption::ramp_then_disable, QuickStopOption::ramp_and_hold}) {
    Cia402StateMachine sm = powered_up(option);
    for (auto cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
      sm.apply_controlword(cw);
    }
    sm.apply_controlword(controlword::quick_stop);
    EXPECT_EQ(sm.state(), DriveState::quick_stop_active);
    EXPECT_EQ(sm.statusword() & 0x6F, 0x07);
    EXPECT_TRUE(sm.braking());
    sm.step(false);  // still moving
    EXPECT_EQ(sm.state(), DriveState::quick_stop_active);
    sm.step(true);
    if (option == QuickStopOption::ramp_then_disable) {
      EXPECT_EQ(sm.state(), DriveState::switch_on_disabled);
    } else {
      EXPECT_EQ(sm.state(), DriveState::quick_stop_active);
      sm.apply_controlword(controlword::enable_operation);
      EXPECT_EQ(sm.state(), DriveState::operation_enabled);
    }
  }
}

TEST(Cia402, FaultNeedsResetEdgeAndClearedCause) {
  Cia402StateMachine sm = powered_up();
  for (auto cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
    sm.apply_controlword(cw);
  }
  sm.raise_fault(0x5000, /*latched_only=*/false);
  EXPECT_EQ(sm.state(), DriveState::fault_reaction_active);
  EXPECT_FALSE(sm.torque_enabled());
  sm.step(false);
  EXPECT_EQ(sm.state(), DriveState::fault);
  EXPECT_EQ(decode_statusword(sm.statusword()), DriveState::fault);
  EXPECT_EQ(sm.error_code(), 0x5000);
  sm.apply_controlword(controlword::fault_reset_bit);  // edge, but the cause is still there
  EXPECT_EQ(sm.state(), DriveState::fault);
  sm.clear_fault_cause();
  sm.apply_controlword(controlword::fault_reset_bit);  // bit still high: no edge
  EXPECT_EQ(sm.state(), DriveState::fault);
  sm.apply_controlword(0);
  sm.apply_controlword(controlword::fault_reset_bit);
  EXPECT_EQ(sm.state(), DriveState::switch_on_disabled);
  EXPECT_EQ(sm.error_code(), 0);
}

TEST(Cia402, DecodesEveryStatewordPatternOfTheReference) {
  EXPECT_EQ(decode_statusword(0x0040), DriveState::switch_on_disabled);
  EXPECT_EQ(decode_statusword(0x0021), DriveState::ready_to_switch_on);
  EXPECT_EQ(decode_statusword(0x0023), DriveState::switched_on);
  EXPECT_EQ(decode_statusword(0x0027), DriveState::operation_enabled);
  EXPECT_EQ(decode_statusword(0x0007), DriveState::quick_stop_active);
  EXPECT_EQ(decode_statusword(0x000F), DriveState::fault_reaction_active);
  EXPECT_EQ(decode_statusword(0x0008), DriveState::fault);
  EXPECT_EQ(decode_statusword(0x1237), DriveState::operation_enabled);  // with extra bits
}

}  // namespace
}  // namespace avs::servo
