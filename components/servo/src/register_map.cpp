#include "avs/servo/register_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace avs::servo {
namespace {

constexpr std::array<std::string_view, signal_count> signal_names = {
    "controlword",     "target_torque", "host_counter",    "mode_of_operation", "max_torque",
    "statusword",      "mode_display",  "torque_actual",   "error_code",        "position_actual",
    "velocity_actual", "echo_counter",  "word_order_probe"};

RegisterSpec spec16(std::uint16_t address, bool is_signed, double scale = 1.0) {
  return RegisterSpec{true, address, 1, is_signed, WordOrder::high_first, scale};
}
RegisterSpec spec32(std::uint16_t address, bool is_signed, double scale = 1.0) {
  return RegisterSpec{true, address, 2, is_signed, WordOrder::high_first, scale};
}

std::int64_t min_counts(const RegisterSpec& s) {
  if (!s.is_signed) return 0;
  return s.width_registers == 1 ? std::numeric_limits<std::int16_t>::min()
                                : std::numeric_limits<std::int32_t>::min();
}
std::int64_t max_counts(const RegisterSpec& s) {
  if (s.width_registers == 1) {
    return s.is_signed ? std::numeric_limits<std::int16_t>::max()
                       : std::numeric_limits<std::uint16_t>::max();
  }
  return s.is_signed ? std::numeric_limits<std::int32_t>::max()
                     : std::numeric_limits<std::uint32_t>::max();
}

}  // namespace

std::string_view signal_name(Signal signal) {
  return signal_names[static_cast<std::size_t>(signal)];
}

std::optional<Signal> signal_from_name(std::string_view name) {
  for (std::size_t i = 0; i < signal_count; ++i) {
    if (signal_names[i] == name) return static_cast<Signal>(i);
  }
  return std::nullopt;
}

std::string_view to_string(WordOrder order) {
  return order == WordOrder::high_first ? "high_first" : "low_first";
}

std::uint16_t RegisterMap::register_count() const {
  std::uint16_t end = 0;
  for (const RegisterSpec& s : specs) {
    if (s.present) end = std::max<std::uint16_t>(end, s.address + s.width_registers);
  }
  return end;
}

RegisterMap default_register_map(double rated_torque_nm, double output_rad_per_count) {
  const double per_mille = rated_torque_nm / 1000.0;
  RegisterMap m;
  m[Signal::controlword] = spec16(0, false);
  m[Signal::target_torque] = spec16(1, true, per_mille);
  m[Signal::host_counter] = spec16(2, false);
  m[Signal::mode_of_operation] = spec16(3, true);
  m[Signal::statusword] = spec16(4, false);
  m[Signal::mode_display] = spec16(5, true);
  m[Signal::torque_actual] = spec16(6, true, per_mille);
  m[Signal::error_code] = spec16(7, false);
  m[Signal::position_actual] = spec32(8, true, output_rad_per_count);
  m[Signal::velocity_actual] = spec32(10, true, output_rad_per_count);
  m[Signal::echo_counter] = spec16(12, false);
  m[Signal::max_torque] = spec16(13, false, per_mille);
  m[Signal::word_order_probe] = spec32(14, false);
  return m;
}

std::int64_t read_counts(const RegisterSpec& spec, std::span<const std::uint16_t> regs) {
  if (spec.width_registers == 1) {
    return spec.is_signed ? static_cast<std::int64_t>(static_cast<std::int16_t>(regs[0]))
                          : static_cast<std::int64_t>(regs[0]);
  }
  const std::uint16_t hi = spec.word_order == WordOrder::high_first ? regs[0] : regs[1];
  const std::uint16_t lo = spec.word_order == WordOrder::high_first ? regs[1] : regs[0];
  const std::uint32_t raw = (static_cast<std::uint32_t>(hi) << 16) | lo;
  return spec.is_signed ? static_cast<std::int64_t>(static_cast<std::int32_t>(raw))
                        : static_cast<std::int64_t>(raw);
}

void write_counts(const RegisterSpec& spec, std::int64_t counts, std::span<std::uint16_t> regs) {
  if (spec.width_registers == 1) {
    regs[0] = static_cast<std::uint16_t>(counts);
    return;
  }
  const auto raw = static_cast<std::uint32_t>(counts);
  const auto hi = static_cast<std::uint16_t>(raw >> 16);
  const auto lo = static_cast<std::uint16_t>(raw & 0xFFFFu);
  regs[0] = spec.word_order == WordOrder::high_first ? hi : lo;
  regs[1] = spec.word_order == WordOrder::high_first ? lo : hi;
}

std::int64_t to_counts(const RegisterSpec& spec, double value_si) {
  const double c = std::round(value_si / spec.scale);
  const double lo = static_cast<double>(min_counts(spec));
  const double hi = static_cast<double>(max_counts(spec));
  if (std::isnan(c)) return 0;
  return static_cast<std::int64_t>(std::clamp(c, lo, hi));
}

double to_si(const RegisterSpec& spec, std::int64_t counts) {
  return static_cast<double>(counts) * spec.scale;
}

void validate(const RegisterMap& map) {
  for (std::size_t i = 0; i < signal_count; ++i) {
    const RegisterSpec& a = map.specs[i];
    if (!a.present) continue;
    const std::string name(signal_names[i]);
    if (a.width_registers != 1 && a.width_registers != 2) {
      throw std::invalid_argument("register " + name + ": size must be 16 or 32 bit");
    }
    if (!(a.scale != 0) || !std::isfinite(a.scale)) {
      throw std::invalid_argument("register " + name + ": scale must be finite and non-zero");
    }
    for (std::size_t j = i + 1; j < signal_count; ++j) {
      const RegisterSpec& b = map.specs[j];
      if (!b.present) continue;
      const bool overlap =
          a.address < b.address + b.width_registers && b.address < a.address + a.width_registers;
      if (overlap) {
        throw std::invalid_argument("registers " + name + " (address " + std::to_string(a.address) +
                                    ") and " + std::string(signal_names[j]) + " (address " +
                                    std::to_string(b.address) + ") overlap");
      }
    }
  }
  for (Signal required : {Signal::controlword, Signal::target_torque, Signal::statusword,
                          Signal::position_actual, Signal::velocity_actual}) {
    if (!map.has(required)) {
      throw std::invalid_argument("register map: required register " +
                                  std::string(signal_name(required)) + " is missing");
    }
  }
}

}  // namespace avs::servo
