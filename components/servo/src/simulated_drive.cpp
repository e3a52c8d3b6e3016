#include "avs/servo/simulated_drive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace avs::servo {

SimulatedDriveConfig pan_drive_config(int unit_id) {
  SimulatedDriveConfig c;
  c.unit_id = unit_id;
  c.plant = pan_plant_config();
  c.rated_torque_nm = pan_rated_torque_nm;
  return c;
}

SimulatedDriveConfig tilt_drive_config(int unit_id) {
  SimulatedDriveConfig c;
  c.unit_id = unit_id;
  c.plant = tilt_plant_config();
  c.rated_torque_nm = tilt_rated_torque_nm;
  c.quick_stop_gain_nm_s_per_rad = 0.1;
  return c;
}

SimulatedDrive::SimulatedDrive(SimulatedDriveConfig config)
    : config_(std::move(config)),
      state_machine_(config_.quick_stop_option),
      plant_(config_.plant),
      max_torque_nm_(config_.plant.max_motor_torque_nm) {
  if (!config_.registers.has(Signal::controlword)) {
    config_.registers =
        default_register_map(config_.rated_torque_nm, plant_.output_rad_per_count());
  }
  validate(config_.registers);
  plant_.reset(config_.initial_q_rad);
}

bool SimulatedDrive::accepts_write(std::uint16_t address, std::size_t count) const {
  static constexpr Signal writable[] = {Signal::controlword, Signal::target_torque,
                                        Signal::host_counter, Signal::mode_of_operation,
                                        Signal::max_torque};
  for (std::size_t i = 0; i < count; ++i) {
    const auto reg = static_cast<std::uint16_t>(address + i);
    bool ok = false;
    for (Signal s : writable) {
      const RegisterSpec& spec = config_.registers[s];
      if (spec.present && reg >= spec.address && reg < spec.address + spec.width_registers)
        ok = true;
    }
    if (!ok) return false;
  }
  return true;
}

void SimulatedDrive::apply_write(std::uint16_t address, std::span<const std::uint16_t> values) {
  const RegisterMap& map = config_.registers;
  // The bank image for the written span, so each signal decodes with its own width/order.
  auto covers = [&](Signal s) {
    const RegisterSpec& spec = map[s];
    return spec.present && spec.address >= address &&
           spec.address + spec.width_registers <= address + values.size();
  };
  auto counts = [&](Signal s) {
    const RegisterSpec& spec = map[s];
    return read_counts(spec, values.subspan(spec.address - address, spec.width_registers));
  };
  // Order within one write: mode, limits and torque before the controlword, so a single
  // 0x17 that writes torque 0 and "enable" never applies a stale torque.
  if (covers(Signal::mode_of_operation)) {
    const auto mode = static_cast<std::int16_t>(counts(Signal::mode_of_operation));
    mode_rejected_ = !is_torque_mode(mode);
    if (!mode_rejected_ && !state_machine_.torque_enabled()) mode_display_ = mode;
  }
  if (covers(Signal::max_torque)) {
    max_torque_nm_ = std::min(to_si(map[Signal::max_torque], counts(Signal::max_torque)),
                              config_.plant.max_motor_torque_nm);
  }
  bool command = false;
  if (covers(Signal::target_torque)) {
    commanded_torque_nm_ = to_si(map[Signal::target_torque], counts(Signal::target_torque));
    command = true;
  }
  if (covers(Signal::host_counter)) {
    if (!echo_frozen_) echo_ = static_cast<std::uint16_t>(counts(Signal::host_counter));
    command = true;
  }
  if (command) {
    last_command_time_s_ = time_s_;
    ++command_writes_;
  }
  if (covers(Signal::controlword)) {
    const bool was_enabled = state_machine_.torque_enabled();
    state_machine_.apply_controlword(static_cast<std::uint16_t>(counts(Signal::controlword)));
    if (!was_enabled && state_machine_.torque_enabled()) last_command_time_s_ = time_s_;
  }
}

double SimulatedDrive::drive_torque_limit_nm() const {
  return std::min(max_torque_nm_, config_.plant.max_motor_torque_nm);
}

double SimulatedDrive::torque_to_apply() const {
  const double limit = drive_torque_limit_nm();
  if (state_machine_.torque_enabled() && is_torque_mode(mode_display_)) {
    return std::clamp(commanded_torque_nm_, -limit, limit);
  }
  if (state_machine_.braking()) {
    return std::clamp(-config_.quick_stop_gain_nm_s_per_rad * plant_.state().qd_rad_s, -limit,
                      limit);
  }
  return 0.0;  // switched off, fault (torque-off reaction), not in a torque mode
}

void SimulatedDrive::step(double dt_s) {
  if (!(dt_s > 0)) return;
  time_s_ += dt_s;
  // Drive-side watchdog: no command for watchdog_timeout_s while enabled -> fault, torque off.
  if (config_.watchdog_timeout_s > 0 && state_machine_.torque_enabled() &&
      time_s_ - last_command_time_s_ >= config_.watchdog_timeout_s - 1e-12) {
    state_machine_.raise_fault(error_code_watchdog);
  }
  state_machine_.step(std::abs(plant_.state().qd_rad_s) < config_.standstill_rad_s);
  applied_torque_nm_ = torque_to_apply();
  plant_.step(dt_s, applied_torque_nm_);
}

void SimulatedDrive::fill_registers(std::span<std::uint16_t> bank) const {
  const RegisterMap& map = config_.registers;
  auto put = [&](Signal s, std::int64_t value) {
    const RegisterSpec& spec = map[s];
    if (!spec.present) return;
    if (spec.address + spec.width_registers > bank.size()) {
      throw std::out_of_range("SimulatedDrive::fill_registers: bank too small");
    }
    write_counts(spec, value, bank.subspan(spec.address, spec.width_registers));
  };
  std::uint16_t extra = 0;
  if (state_machine_.torque_enabled() && is_torque_mode(mode_display_)) {
    extra |= statusword::follows_command;
  }
  if (mode_rejected_) extra |= statusword::warning;
  if (state_machine_.torque_enabled() && std::abs(commanded_torque_nm_) > drive_torque_limit_nm()) {
    extra |= statusword::internal_limit_active;
  }
  put(Signal::statusword, state_machine_.statusword(extra));
  put(Signal::mode_display, mode_display_);
  if (map.has(Signal::torque_actual)) {
    put(Signal::torque_actual, to_counts(map[Signal::torque_actual], applied_torque_nm_));
  }
  put(Signal::error_code, state_machine_.error_code());
  // Encoder quantisation: floor to counts, wrapping like an INT32 position register.
  const RegisterSpec& pos = map[Signal::position_actual];
  const auto pos_counts = static_cast<std::int64_t>(std::floor(plant_.state().q_rad / pos.scale));
  put(Signal::position_actual, static_cast<std::int32_t>(static_cast<std::uint32_t>(pos_counts)));
  put(Signal::velocity_actual,
      to_counts(map[Signal::velocity_actual],
                std::trunc(plant_.state().qd_rad_s / map[Signal::velocity_actual].scale) *
                    map[Signal::velocity_actual].scale));
  put(Signal::echo_counter, echo_);
  put(Signal::word_order_probe, word_order_probe_value);
}

}  // namespace avs::servo
