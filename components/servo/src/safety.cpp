#include "avs/servo/safety.hpp"

#include <algorithm>
#include <cmath>

namespace avs::servo {

std::string describe_safety_reasons(std::uint32_t reasons) {
  static constexpr std::pair<std::uint32_t, const char*> names[] = {
      {safety_estop, "e-stop"},
      {safety_no_command, "no command"},
      {safety_command_stale, "command stale"},
      {safety_link_fault, "link fault"},
      {safety_drive_not_enabled, "drive not enabled"},
      {safety_torque_clamped, "torque clamped"},
      {safety_soft_limit_block, "soft limit block"},
      {safety_soft_limit_brake, "soft limit brake"},
      {safety_feedback_invalid, "feedback invalid"},
  };
  std::string out;
  for (const auto& [bit, name] : names) {
    if ((reasons & bit) == 0) continue;
    if (!out.empty()) out += ", ";
    out += name;
  }
  return out.empty() ? "none" : out;
}

SafetyOutput apply_safety(const AxisSafetyConfig& config, double command_timeout_s,
                          const SafetyInput& in) {
  SafetyOutput out;
  // 1. Conditions under which no torque is allowed at all.
  if (in.estop) out.reasons |= safety_estop;
  if (!in.link_healthy) out.reasons |= safety_link_fault;
  if (!in.drive_enabled) out.reasons |= safety_drive_not_enabled;
  if (!in.feedback_valid) out.reasons |= safety_feedback_invalid;
  if (std::isnan(in.command_stamp_s)) {
    out.reasons |= safety_no_command;
  } else if (in.now_s - in.command_stamp_s > command_timeout_s) {
    out.reasons |= safety_command_stale;
  }
  if (out.reasons != safety_none) return out;  // torque 0

  // 2. Torque limit: the smaller of the configured and the motor limit.
  const double limit =
      std::max(0.0, std::min(config.configured_max_torque_nm, config.motor_max_torque_nm));
  double tau = std::isfinite(in.command_nm) ? in.command_nm : 0.0;
  if (std::abs(tau) > limit) {
    tau = std::clamp(tau, -limit, limit);
    out.reasons |= safety_torque_clamped;
  }

  // 3. Soft position limits. Past a limit: never push further out. Near a limit (or past it)
  // while moving outward: brake with torque opposing the motion.
  const double brake = config.brake_gain_nm_s_per_rad * std::abs(in.qd_rad_s);
  if (in.q_rad >= config.soft_upper_rad && tau > 0) {
    tau = 0;
    out.reasons |= safety_soft_limit_block;
  }
  if (in.q_rad <= config.soft_lower_rad && tau < 0) {
    tau = 0;
    out.reasons |= safety_soft_limit_block;
  }
  if (in.q_rad > config.soft_upper_rad - config.brake_zone_rad && in.qd_rad_s > 0 && tau > -brake) {
    tau = -brake;
    out.reasons |= safety_soft_limit_brake;
  }
  if (in.q_rad < config.soft_lower_rad + config.brake_zone_rad && in.qd_rad_s < 0 && tau < brake) {
    tau = brake;
    out.reasons |= safety_soft_limit_brake;
  }
  out.torque_nm = std::clamp(tau, -limit, limit);
  return out;
}

}  // namespace avs::servo
