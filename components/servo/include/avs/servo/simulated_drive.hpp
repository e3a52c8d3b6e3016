// One simulated torque-mode servo amplifier (one Modbus unit): CiA 402 state machine + axis
// plant + drive-side command watchdog behind a register map. Pure core, no I/O: the Modbus
// server (amplifier_server.hpp) feeds it register writes and copies its registers out.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "avs/servo/cia402.hpp"
#include "avs/servo/plant.hpp"
#include "avs/servo/register_map.hpp"

namespace avs::servo {

struct SimulatedDriveConfig {
  int unit_id = 1;
  AxisPlantConfig plant = pan_plant_config();
  RegisterMap registers;  ///< empty (no controlword) = default_register_map for this plant
  double rated_torque_nm = pan_rated_torque_nm;
  /// No target-torque or host-counter write for this long while enabled -> fault 0x8130
  /// (torque off). 0 disables the watchdog.
  double watchdog_timeout_s = 0.002;
  QuickStopOption quick_stop_option = QuickStopOption::ramp_then_disable;
  double quick_stop_gain_nm_s_per_rad = 0.5;  ///< braking torque per output rad/s in quick stop
  double standstill_rad_s = 1e-3;             ///< quick stop finishes below this speed
  double initial_q_rad = 0;
};

SimulatedDriveConfig pan_drive_config(int unit_id = 1);
SimulatedDriveConfig tilt_drive_config(int unit_id = 2);

/// CiA 402 error codes used by the simulation.
inline constexpr std::uint16_t error_code_watchdog = 0x8130;  ///< life guard / heartbeat
inline constexpr std::uint16_t error_code_injected = 0x5000;  ///< device hardware (injected)

class SimulatedDrive {
 public:
  explicit SimulatedDrive(SimulatedDriveConfig config);

  /// True when [address, address + count) only touches writable registers of the map.
  bool accepts_write(std::uint16_t address, std::size_t count) const;
  /// Applies a register write received at drive time `time_s()` (controlword -> state machine,
  /// torque command, heartbeat counter, mode, max torque).
  void apply_write(std::uint16_t address, std::span<const std::uint16_t> values);
  /// Writes the drive-produced registers (statusword, actual values, echo, probe) into `bank`
  /// (indexed by address, at least registers().register_count() long).
  void fill_registers(std::span<std::uint16_t> bank) const;

  /// Advances drive time and the plant by dt_s; runs the watchdog and automatic transitions.
  void step(double dt_s);

  // Fault injection.
  void raise_fault(std::uint16_t error_code, bool latched_only = true) {
    state_machine_.raise_fault(error_code, latched_only);
  }
  void clear_fault_cause() { state_machine_.clear_fault_cause(); }
  void leave_fault_without_reset() { state_machine_.leave_fault_without_reset(); }
  /// The echo register stops following the host counter (a stale-reply source).
  void set_echo_frozen(bool frozen) { echo_frozen_ = frozen; }

  // Inspection.
  const Cia402StateMachine& state_machine() const { return state_machine_; }
  const AxisPlant& plant() const { return plant_; }
  AxisPlant& plant() { return plant_; }
  const RegisterMap& registers() const { return config_.registers; }
  const SimulatedDriveConfig& config() const { return config_; }
  double applied_torque_nm() const { return applied_torque_nm_; }
  double commanded_torque_nm() const { return commanded_torque_nm_; }
  std::int16_t mode_display() const { return mode_display_; }
  double time_s() const { return time_s_; }
  std::uint64_t command_writes() const { return command_writes_; }

 private:
  double torque_to_apply() const;
  double drive_torque_limit_nm() const;

  SimulatedDriveConfig config_;
  Cia402StateMachine state_machine_;
  AxisPlant plant_;
  double time_s_ = 0;
  double last_command_time_s_ = 0;
  double commanded_torque_nm_ = 0;  ///< as quantised from the register
  double applied_torque_nm_ = 0;
  double max_torque_nm_;  ///< 0x6072, defaults to the motor limit
  std::int16_t mode_display_ = 0;
  bool mode_rejected_ = false;
  std::uint16_t echo_ = 0;
  bool echo_frozen_ = false;
  std::uint64_t command_writes_ = 0;
};

}  // namespace avs::servo
