// Host-side safety rules applied to every torque command before it goes on the bus (issue 5
// item 4). Pure function of the inputs; the drive client calls it once per axis per cycle.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace avs::servo {

struct AxisSafetyConfig {
  double configured_max_torque_nm = 5.73;  ///< operator limit (motor side)
  double motor_max_torque_nm = 5.73;       ///< Table 3 motor limit
  double soft_lower_rad = -std::numeric_limits<double>::infinity();
  double soft_upper_rad = std::numeric_limits<double>::infinity();
  double brake_zone_rad = 0.1;  ///< inside this distance of a limit, moving outward brakes
  double brake_gain_nm_s_per_rad = 0.05;  ///< braking torque per output rad/s toward the limit
};

/// Why the safe torque differs from the command (bit set).
enum SafetyReason : std::uint32_t {
  safety_none = 0,
  safety_estop = 1u << 0,
  safety_no_command = 1u << 1,
  safety_command_stale = 1u << 2,
  safety_link_fault = 1u << 3,
  safety_drive_not_enabled = 1u << 4,
  safety_torque_clamped = 1u << 5,
  safety_soft_limit_block = 1u << 6,
  safety_soft_limit_brake = 1u << 7,
  safety_feedback_invalid = 1u << 8,
};
std::string describe_safety_reasons(std::uint32_t reasons);

struct SafetyInput {
  double command_nm = 0;
  double command_stamp_s = std::numeric_limits<double>::quiet_NaN();  ///< NaN: no command yet
  double now_s = 0;
  bool estop = false;
  bool link_healthy = true;
  bool drive_enabled = true;   ///< last statusword said Operation enabled
  bool feedback_valid = true;  ///< q and qd below are from this link's last good exchange
  double q_rad = 0;
  double qd_rad_s = 0;
};

struct SafetyOutput {
  double torque_nm = 0;
  std::uint32_t reasons = safety_none;
};

/// Rules, in order: e-stop, link fault, drive not enabled, invalid feedback, missing or stale
/// command (older than command_timeout_s) -> 0; clamp to min(configured, motor) limit; soft
/// position limits: no torque pushing past a limit, braking when moving outward near it.
SafetyOutput apply_safety(const AxisSafetyConfig& config, double command_timeout_s,
                          const SafetyInput& input);

}  // namespace avs::servo
