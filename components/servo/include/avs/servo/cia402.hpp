// CiA 402 (IEC 61800-7) drive state machine: controlword 0x6040 in, statusword 0x6041 out.
// Pure logic, no I/O: the simulated amplifier owns one per axis and the drive client uses the
// decoding helpers. Bit patterns: shared/reference/servo-modbus-cia402.md sections 2.1-2.3.
#pragma once

#include <cstdint>
#include <string_view>

namespace avs::servo {

enum class DriveState : std::uint8_t {
  not_ready_to_switch_on,
  switch_on_disabled,
  ready_to_switch_on,
  switched_on,
  operation_enabled,
  quick_stop_active,
  fault_reaction_active,
  fault,
};

std::string_view to_string(DriveState state);

/// Controlword command values (bits 7..0).
namespace controlword {
inline constexpr std::uint16_t disable_voltage = 0x0000;
inline constexpr std::uint16_t quick_stop = 0x0002;
inline constexpr std::uint16_t shutdown = 0x0006;
inline constexpr std::uint16_t switch_on = 0x0007;  ///< also "disable operation"
inline constexpr std::uint16_t enable_operation = 0x000F;
inline constexpr std::uint16_t fault_reset_bit = 0x0080;  ///< acts on a 0 -> 1 edge
}  // namespace controlword

/// Statusword bits beyond the state pattern.
namespace statusword {
inline constexpr std::uint16_t voltage_enabled = 1u << 4;
inline constexpr std::uint16_t warning = 1u << 7;
inline constexpr std::uint16_t remote = 1u << 9;
inline constexpr std::uint16_t internal_limit_active = 1u << 11;
inline constexpr std::uint16_t follows_command = 1u << 12;  ///< cyclic modes: drive follows command
}  // namespace statusword

/// Decodes the state from a statusword with the masks of reference table 2.2.
DriveState decode_statusword(std::uint16_t statusword);

/// Modes of operation (0x6060/0x6061) the simulated amplifier supports: both apply the torque
/// command directly (profile-torque ramping is not modelled).
inline constexpr std::int16_t mode_profile_torque = 4;
inline constexpr std::int16_t mode_cyclic_synchronous_torque = 10;
bool is_torque_mode(std::int16_t mode);

enum class QuickStopOption : std::uint8_t {
  ramp_then_disable,  ///< 0x605A = 2: brake, then Switch on disabled
  ramp_and_hold,      ///< 0x605A = 6: brake and stay in Quick stop active
};

/// The drive side of CiA 402: transitions on controlword writes plus the automatic ones
/// (power-up, fault reaction finished, quick stop finished).
class Cia402StateMachine {
 public:
  explicit Cia402StateMachine(QuickStopOption option = QuickStopOption::ramp_then_disable)
      : quick_stop_option_(option) {}

  /// Applies one controlword write (reference table 2.3). Fault reset acts on the 0 -> 1 edge
  /// of bit 7 and only once the fault cause is gone.
  void apply_controlword(std::uint16_t controlword);

  /// Any state -> Fault reaction active; `error_code` is kept for 0x603F. The cause stays active
  /// until clear_fault_cause() unless `latched_only` (cause already gone, only a reset needed).
  void raise_fault(std::uint16_t error_code, bool latched_only = true);
  void clear_fault_cause() { fault_cause_active_ = false; }
  /// Fault injection: Fault (or Fault reaction active) -> Operation enabled without a reset,
  /// as a drive that clears a fault on its own or a corrupted statusword would report.
  void leave_fault_without_reset();

  /// Automatic transitions: Not ready -> Switch on disabled, Fault reaction -> Fault (torque off
  /// reaction), Quick stop active -> Switch on disabled once `motion_stopped` (option 2).
  void step(bool motion_stopped);

  DriveState state() const { return state_; }
  std::uint16_t error_code() const { return error_code_; }
  /// Statusword with the state pattern, voltage-enabled, remote and the given extra bits.
  std::uint16_t statusword(std::uint16_t extra_bits = 0) const;
  bool torque_enabled() const { return state_ == DriveState::operation_enabled; }
  bool braking() const { return state_ == DriveState::quick_stop_active; }

 private:
  QuickStopOption quick_stop_option_;
  DriveState state_ = DriveState::not_ready_to_switch_on;
  std::uint16_t last_controlword_ = 0;
  std::uint16_t error_code_ = 0;
  bool fault_cause_active_ = false;
};

}  // namespace avs::servo
