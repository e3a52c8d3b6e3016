// Data-driven Modbus register map of one axis (one unit id): which holding register carries
// which CiA 402 signal, in how many registers, in which word order, with which scale to SI.
// The default map is the simulated amplifier's and is documented in docs/servo.md.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace avs::servo {

enum class Signal : std::uint8_t {
  controlword,        ///< 0x6040, written
  target_torque,      ///< 0x6071, written, motor N m per count
  host_counter,       ///< heartbeat written by the host every cycle
  mode_of_operation,  ///< 0x6060, written at configure
  max_torque,         ///< 0x6072, written at configure, motor N m per count
  statusword,         ///< 0x6041
  mode_display,       ///< 0x6061
  torque_actual,      ///< 0x6077, motor N m per count
  error_code,         ///< 0x603F
  position_actual,    ///< 0x6064, output rad per count
  velocity_actual,    ///< 0x606C, output rad/s per count
  echo_counter,       ///< the drive's copy of host_counter (stale-reply check)
  word_order_probe,   ///< 32-bit constant 0x12345678 (word order check at configure)
};
inline constexpr std::size_t signal_count = 13;
inline constexpr std::uint32_t word_order_probe_value = 0x12345678u;

std::string_view signal_name(Signal signal);
std::optional<Signal> signal_from_name(std::string_view name);

enum class WordOrder : std::uint8_t { high_first, low_first };
std::string_view to_string(WordOrder order);

struct RegisterSpec {
  bool present = false;
  std::uint16_t address = 0;
  std::uint8_t width_registers = 1;  ///< 1 (16 bit) or 2 (32 bit)
  bool is_signed = false;
  WordOrder word_order = WordOrder::high_first;
  double scale = 1.0;  ///< SI units per count
};

struct RegisterMap {
  std::array<RegisterSpec, signal_count> specs{};

  RegisterSpec& operator[](Signal s) { return specs[static_cast<std::size_t>(s)]; }
  const RegisterSpec& operator[](Signal s) const { return specs[static_cast<std::size_t>(s)]; }
  bool has(Signal s) const { return (*this)[s].present; }
  /// One past the highest register address used.
  std::uint16_t register_count() const;
};

/// The simulated amplifier's map for an axis with the given rated torque and scales:
///   0 controlword, 1 target_torque (i16, per mille of rated), 2 host_counter, 3 mode_of_operation,
///   4 statusword, 5 mode_display, 6 torque_actual (i16 per mille), 7 error_code,
///   8-9 position_actual (i32), 10-11 velocity_actual (i32 counts/s), 12 echo_counter,
///   13 max_torque (u16 per mille), 14-15 word_order_probe (u32); 32-bit values high word first.
RegisterMap default_register_map(double rated_torque_nm, double output_rad_per_count);

/// Rated torques behind the per-mille torque registers: Table 3 peak / 3 (assumption: peak is
/// 300 % of rated, as for the SGMAS series).
inline constexpr double pan_rated_torque_nm = 5.73 / 3.0;
inline constexpr double tilt_rated_torque_nm = 0.9555 / 3.0;

/// Raw register value <-> counts. `regs` starts at spec.address.
std::int64_t read_counts(const RegisterSpec& spec, std::span<const std::uint16_t> regs);
void write_counts(const RegisterSpec& spec, std::int64_t counts, std::span<std::uint16_t> regs);

/// SI value <-> counts with rounding and saturation to the register's range.
std::int64_t to_counts(const RegisterSpec& spec, double value_si);
double to_si(const RegisterSpec& spec, std::int64_t counts);

/// Throws std::invalid_argument naming the signal when a spec is inconsistent (width not 1/2,
/// zero scale) or when two present signals overlap.
void validate(const RegisterMap& map);

}  // namespace avs::servo
