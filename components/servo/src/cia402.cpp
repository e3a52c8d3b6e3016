#include "avs/servo/cia402.hpp"

namespace avs::servo {
namespace {

// Command decoding by the standard bit masks (reference 2.3); order matters: disable voltage
// (bit 1 = 0) wins over quick stop (bit 2 = 0) which wins over the rest.
bool is_disable_voltage(std::uint16_t cw) {
  return (cw & 0x0002u) == 0;
}
bool is_quick_stop(std::uint16_t cw) {
  return (cw & 0x0006u) == 0x0002u;
}
bool is_shutdown(std::uint16_t cw) {
  return (cw & 0x0007u) == 0x0006u;
}
bool is_switch_on(std::uint16_t cw) {
  return (cw & 0x0007u) == 0x0007u;
}
bool is_enable_operation(std::uint16_t cw) {
  return (cw & 0x000Fu) == 0x000Fu;
}

}  // namespace

std::string_view to_string(DriveState state) {
  switch (state) {
    case DriveState::not_ready_to_switch_on:
      return "not ready to switch on";
    case DriveState::switch_on_disabled:
      return "switch on disabled";
    case DriveState::ready_to_switch_on:
      return "ready to switch on";
    case DriveState::switched_on:
      return "switched on";
    case DriveState::operation_enabled:
      return "operation enabled";
    case DriveState::quick_stop_active:
      return "quick stop active";
    case DriveState::fault_reaction_active:
      return "fault reaction active";
    case DriveState::fault:
      return "fault";
  }
  return "unknown";
}

DriveState decode_statusword(std::uint16_t sw) {
  switch (sw & 0x004Fu) {
    case 0x0000:
      return DriveState::not_ready_to_switch_on;
    case 0x0040:
      return DriveState::switch_on_disabled;
    case 0x000F:
      return DriveState::fault_reaction_active;
    case 0x0008:
      return DriveState::fault;
    default:
      break;
  }
  switch (sw & 0x006Fu) {
    case 0x0021:
      return DriveState::ready_to_switch_on;
    case 0x0023:
      return DriveState::switched_on;
    case 0x0027:
      return DriveState::operation_enabled;
    case 0x0007:
      return DriveState::quick_stop_active;
    default:
      break;
  }
  // Patterns outside the table (e.g. fault bit with others set) are treated as a fault.
  return DriveState::fault;
}

bool is_torque_mode(std::int16_t mode) {
  return mode == mode_profile_torque || mode == mode_cyclic_synchronous_torque;
}

void Cia402StateMachine::apply_controlword(std::uint16_t cw) {
  const bool reset_edge = (cw & controlword::fault_reset_bit) != 0 &&
                          (last_controlword_ & controlword::fault_reset_bit) == 0;
  last_controlword_ = cw;
  if (state_ == DriveState::fault) {
    if (reset_edge && !fault_cause_active_) {
      state_ = DriveState::switch_on_disabled;
      error_code_ = 0;
    }
    return;
  }
  if ((cw & controlword::fault_reset_bit) != 0) return;  // bit 7 high: no other command
  switch (state_) {
    case DriveState::not_ready_to_switch_on:
    case DriveState::fault_reaction_active:
    case DriveState::fault:
      return;
    case DriveState::switch_on_disabled:
      if (!is_disable_voltage(cw) && !is_quick_stop(cw) && is_shutdown(cw)) {
        state_ = DriveState::ready_to_switch_on;
      }
      return;
    case DriveState::ready_to_switch_on:
      if (is_disable_voltage(cw) || is_quick_stop(cw)) {
        state_ = DriveState::switch_on_disabled;
      } else if (is_switch_on(cw)) {
        state_ = DriveState::switched_on;
      }
      return;
    case DriveState::switched_on:
      if (is_disable_voltage(cw) || is_quick_stop(cw)) {
        state_ = DriveState::switch_on_disabled;
      } else if (is_shutdown(cw)) {
        state_ = DriveState::ready_to_switch_on;
      } else if (is_enable_operation(cw)) {
        state_ = DriveState::operation_enabled;
      }
      return;
    case DriveState::operation_enabled:
      if (is_disable_voltage(cw)) {
        state_ = DriveState::switch_on_disabled;
      } else if (is_quick_stop(cw)) {
        state_ = DriveState::quick_stop_active;
      } else if (is_shutdown(cw)) {
        state_ = DriveState::ready_to_switch_on;
      } else if (!is_enable_operation(cw)) {
        state_ = DriveState::switched_on;  // disable operation 0x07
      }
      return;
    case DriveState::quick_stop_active:
      if (is_disable_voltage(cw)) {
        state_ = DriveState::switch_on_disabled;
      } else if (is_enable_operation(cw) && quick_stop_option_ == QuickStopOption::ramp_and_hold) {
        state_ = DriveState::operation_enabled;
      }
      return;
  }
}

void Cia402StateMachine::raise_fault(std::uint16_t error_code, bool latched_only) {
  error_code_ = error_code;
  fault_cause_active_ = !latched_only;
  if (state_ != DriveState::fault) state_ = DriveState::fault_reaction_active;
}

void Cia402StateMachine::leave_fault_without_reset() {
  if (state_ != DriveState::fault && state_ != DriveState::fault_reaction_active) return;
  state_ = DriveState::operation_enabled;
  error_code_ = 0;
  fault_cause_active_ = false;
}

void Cia402StateMachine::step(bool motion_stopped) {
  switch (state_) {
    case DriveState::not_ready_to_switch_on:
      state_ = DriveState::switch_on_disabled;
      break;
    case DriveState::fault_reaction_active:
      state_ = DriveState::fault;
      break;
    case DriveState::quick_stop_active:
      if (motion_stopped && quick_stop_option_ == QuickStopOption::ramp_then_disable) {
        state_ = DriveState::switch_on_disabled;
      }
      break;
    default:
      break;
  }
}

std::uint16_t Cia402StateMachine::statusword(std::uint16_t extra_bits) const {
  std::uint16_t pattern = 0;
  switch (state_) {
    case DriveState::not_ready_to_switch_on:
      pattern = 0x0000;
      break;
    case DriveState::switch_on_disabled:
      pattern = 0x0040;
      break;
    case DriveState::ready_to_switch_on:
      pattern = 0x0021 | statusword::voltage_enabled;
      break;
    case DriveState::switched_on:
      pattern = 0x0023 | statusword::voltage_enabled;
      break;
    case DriveState::operation_enabled:
      pattern = 0x0027 | statusword::voltage_enabled;
      break;
    case DriveState::quick_stop_active:
      pattern = 0x0007 | statusword::voltage_enabled;
      break;
    case DriveState::fault_reaction_active:
      pattern = 0x000F;
      break;
    case DriveState::fault:
      pattern = 0x0008;
      break;
  }
  return static_cast<std::uint16_t>(pattern | statusword::remote | extra_bits);
}

}  // namespace avs::servo
