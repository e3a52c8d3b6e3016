#include "avs/servo/safety.hpp"

#include "avs/servo/plant.hpp"

#include <algorithm>
#include <cmath>

namespace avs::servo {
namespace {

double torque_limit_nm(const AxisSafetyConfig& config) {
  return std::max(0.0, std::min(config.configured_max_torque_nm, config.motor_max_torque_nm));
}

bool envelope_enabled(const AxisSafetyConfig& config) {
  return config.output_inertia_kg_m2 > 0 && config.envelope_brake_fraction > 0 &&
         config.gear_ratio > 0 && config.gear_efficiency > 0;
}

}  // namespace

namespace {

AxisSafetyConfig safety_of_plant(const AxisPlantConfig& plant, double soft_limit_rad,
                                 double brake_gain_nm_s_per_rad) {
  AxisSafetyConfig c;
  c.configured_max_torque_nm = plant.max_motor_torque_nm;
  c.motor_max_torque_nm = plant.max_motor_torque_nm;
  c.soft_lower_rad = -soft_limit_rad;
  c.soft_upper_rad = soft_limit_rad;
  c.brake_gain_nm_s_per_rad = brake_gain_nm_s_per_rad;
  c.output_inertia_kg_m2 = plant.inertia_kgm2;
  c.gear_ratio = plant.gear_ratio;
  c.gear_efficiency = plant.efficiency;
  return c;
}

}  // namespace

AxisSafetyConfig pan_safety_config() {
  return safety_of_plant(pan_plant_config(), 3.0, 0.05);
}

AxisSafetyConfig tilt_safety_config() {
  return safety_of_plant(tilt_plant_config(), 1.4, 0.01);
}

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
      {safety_command_future, "command from the future"},
      {safety_fault_latched, "fault latched"},
      {safety_soft_limit_envelope, "soft limit envelope"},
  };
  std::string out;
  for (const auto& [bit, name] : names) {
    if ((reasons & bit) == 0) continue;
    if (!out.empty()) out += ", ";
    out += name;
  }
  return out.empty() ? "none" : out;
}

bool is_future_stamped(const CommandFreshness& freshness, double stamp_s, double arrival_s) {
  return stamp_s - arrival_s > freshness.future_tolerance_s;
}

double envelope_max_torque_nm(const AxisSafetyConfig& config, double upper_limit_rad,
                              const SafetyInput& in) {
  constexpr double unlimited = std::numeric_limits<double>::infinity();
  if (!envelope_enabled(config) || !std::isfinite(upper_limit_rad)) return unlimited;
  // Output acceleration per motor N m (friction ignored: it only helps to stop).
  const double accel_per_nm = config.gear_efficiency * config.gear_ratio /
                              config.output_inertia_kg_m2;
  const double brake_rad_s2 =
      config.envelope_brake_fraction * accel_per_nm * torque_limit_nm(config);
  if (!(brake_rad_s2 > 0)) return unlimited;
  // 1. Where the axis is when this command starts to act: the previous torque acts meanwhile.
  const double age_s = std::max(0.0, in.feedback_age_s);
  const double previous_rad_s2 = accel_per_nm * in.previous_torque_nm;
  const double q1 = in.q_rad + in.qd_rad_s * age_s + 0.5 * previous_rad_s2 * age_s * age_s;
  const double v1 = in.qd_rad_s + previous_rad_s2 * age_s;
  // 2. Without a hold time the command cannot change where the next decision starts from:
  // inside the envelope anything goes, outside it only full braking.
  const double hold_s = std::max(0.0, in.command_hold_s);
  if (hold_s == 0) {
    const bool outside = v1 > 0 && v1 * v1 > 2 * brake_rad_s2 * (upper_limit_rad - q1);
    return outside ? -unlimited : unlimited;
  }
  // 3. After the hold the axis is at q2 = q1 + h (v1 + v2) / 2 with speed v2, and from there
  // it must stop before the limit: v2^2 / (2 a_brake) + v2 h / 2 <= limit - q2, where the
  // v2 h / 2 is the last hold, which cannot brake harder than "to rest within one period".
  // The largest v2 solves v2^2 + 2 a_brake h v2 - 2 a_brake R = 0, R = limit - q1 - h v1 / 2.
  const double room_rad = upper_limit_rad - q1 - 0.5 * hold_s * v1;
  const double b = brake_rad_s2 * hold_s;
  const double discriminant = b * b + 2 * brake_rad_s2 * room_rad;
  const double v2_max = discriminant >= 0 ? std::max(0.0, -b + std::sqrt(discriminant))
                                          : 0.0;  // no room left: stop as hard as possible
  return (v2_max - v1) / hold_s / accel_per_nm;
}

SafetyOutput apply_safety(const AxisSafetyConfig& config, const CommandFreshness& freshness,
                          const SafetyInput& in) {
  SafetyOutput out;
  // 1. Conditions under which no torque is allowed at all.
  if (in.estop) out.reasons |= safety_estop;
  if (!in.link_healthy) out.reasons |= safety_link_fault;
  if (!in.drive_enabled) out.reasons |= safety_drive_not_enabled;
  if (in.fault_latched) out.reasons |= safety_fault_latched;
  if (!in.feedback_valid) out.reasons |= safety_feedback_invalid;
  if (std::isnan(in.command_stamp_s)) {
    out.reasons |= safety_no_command;
  } else if (is_future_stamped(freshness, in.command_stamp_s, in.now_s)) {
    out.reasons |= safety_command_future;
  } else if (in.now_s - in.command_stamp_s > freshness.timeout_s ||
             in.now_s - in.command_arrival_s > freshness.timeout_s) {
    // Either age counts: the stamp says when it was computed, the arrival when we got it
    // (a stamp a little ahead within the tolerance must not extend its life).
    out.reasons |= safety_command_stale;
  }
  if (out.reasons != safety_none) return out;  // torque 0

  // 2. Torque limit: the smaller of the configured and the motor limit.
  const double limit = torque_limit_nm(config);
  double tau = std::isfinite(in.command_nm) ? in.command_nm : 0.0;
  if (std::abs(tau) > limit) {
    tau = std::clamp(tau, -limit, limit);
    out.reasons |= safety_torque_clamped;
  }

  // 3. Velocity envelope: toward a limit no torque that would take the axis faster than it can
  // still stop from with the planned braking deceleration; above it, braking torque instead.
  const double max_up_nm = envelope_max_torque_nm(config, config.soft_upper_rad, in);
  if (tau > max_up_nm) {
    tau = std::max(max_up_nm, -limit);
    out.reasons |= safety_soft_limit_envelope;
  }
  SafetyInput mirrored = in;  // the lower limit is the upper one of the mirrored axis
  mirrored.q_rad = -in.q_rad;
  mirrored.qd_rad_s = -in.qd_rad_s;
  mirrored.previous_torque_nm = -in.previous_torque_nm;
  const double max_down_nm = envelope_max_torque_nm(config, -config.soft_lower_rad, mirrored);
  if (-tau > max_down_nm) {
    tau = std::min(-max_down_nm, limit);
    out.reasons |= safety_soft_limit_envelope;
  }

  // 4. Soft position limits. Past a limit: never push further out. Near a limit (or past it)
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

bool FaultLatch::update(DriveState state, bool reset_requested) {
  if (state == DriveState::fault || state == DriveState::fault_reaction_active) {
    latched_ = true;
    // A fault seen while no reset is pending needs a new request (a reset that has already
    // been acted on does not cover a fault that comes back).
    reset_seen_ = reset_requested;
    enabled_cycles_ = 0;
    return latched_;
  }
  if (!latched_) return false;
  if (reset_requested) reset_seen_ = true;
  enabled_cycles_ = reset_seen_ && state == DriveState::operation_enabled ? enabled_cycles_ + 1 : 0;
  if (enabled_cycles_ >= stable_cycles_) {
    latched_ = false;
    reset_seen_ = false;
    enabled_cycles_ = 0;
  }
  return latched_;
}

}  // namespace avs::servo
