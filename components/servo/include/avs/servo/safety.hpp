// Host-side safety rules applied to every torque command before it goes on the bus (issue 5
// item 4, issue 20 section 1). Pure functions of the inputs plus one small per-axis latch; the
// drive client calls them once per axis per cycle.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "avs/servo/cia402.hpp"

namespace avs::servo {

struct AxisSafetyConfig {
  double configured_max_torque_nm = 5.73;  ///< operator limit (motor side)
  double motor_max_torque_nm = 5.73;       ///< Table 3 motor limit
  double soft_lower_rad = -std::numeric_limits<double>::infinity();
  double soft_upper_rad = std::numeric_limits<double>::infinity();
  double brake_zone_rad = 0.1;  ///< inside this distance of a limit, moving outward brakes
  double brake_gain_nm_s_per_rad = 0.05;  ///< braking torque per output rad/s toward the limit
  // Velocity envelope of the soft limits (issue 20 1.4): the axis may move toward a limit only
  // as fast as it can still stop before it, v_max(d) = sqrt(2 a_brake d), with
  // a_brake = envelope_brake_fraction x gear_efficiency x gear_ratio x max torque / inertia.
  // Defaults: the pan axis of the plant model (plant.hpp, reference 4).
  double output_inertia_kg_m2 = 0.00598;  ///< J_eq at the output; <= 0: no envelope
  double gear_ratio = 4.2;                ///< N, motor turns per output turn
  double gear_efficiency = 0.95;          ///< eta
  /// Share of the full braking deceleration the envelope plans with; the rest is the margin
  /// for model error (inertia, efficiency) and a late cycle. (0, 1]; <= 0: no envelope.
  double envelope_brake_fraction = 0.5;
};

/// The safety rules of the paper's head, per axis: the motor limits of Table 3, the soft limits
/// of our pan (+-3.0 rad) and tilt (+-1.4 rad) travel, and the envelope's inertia and gearing
/// from the plant model (plant.hpp). servo_drive's per-axis defaults come from these.
AxisSafetyConfig pan_safety_config();
AxisSafetyConfig tilt_safety_config();

/// When a torque command is fresh (issue 20 1.1).
struct CommandFreshness {
  double timeout_s = 0.02;  ///< stale when its stamp or its arrival is older than this
  /// A stamp later than the arrival (or now) by more than this is rejected: a sender clock
  /// ahead of ours would otherwise keep one command applied until its stamp ages.
  double future_tolerance_s = 0.005;
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
  safety_command_future = 1u << 9,
  safety_fault_latched = 1u << 10,
  safety_soft_limit_envelope = 1u << 11,
};
std::string describe_safety_reasons(std::uint32_t reasons);

struct SafetyInput {
  double command_nm = 0;
  double command_stamp_s = std::numeric_limits<double>::quiet_NaN();  ///< NaN: no command yet
  /// When the command arrived (receiver's clock); NaN: the arrival rule is not applied.
  double command_arrival_s = std::numeric_limits<double>::quiet_NaN();
  double now_s = 0;
  bool estop = false;
  bool link_healthy = true;
  bool drive_enabled = true;   ///< last statusword said Operation enabled
  bool fault_latched = false;  ///< FaultLatch: a drive fault not yet reset and confirmed
  bool feedback_valid = true;  ///< q and qd below are from this link's last good exchange
  double q_rad = 0;
  double qd_rad_s = 0;
  // Timing of the cycle, for the velocity envelope: the feedback above is feedback_age_s old
  // when this command starts to act; until then previous_torque_nm (already written) acts;
  // this command then holds for command_hold_s (one period). Zeros: no latency modelled.
  double previous_torque_nm = 0;
  double feedback_age_s = 0;
  double command_hold_s = 0;
};

struct SafetyOutput {
  double torque_nm = 0;
  std::uint32_t reasons = safety_none;
};

/// True when a command stamped `stamp_s` that arrived at `arrival_s` claims to come from the
/// future by more than the tolerance (a clock ahead of ours, or a bad stamp).
bool is_future_stamped(const CommandFreshness& freshness, double stamp_s, double arrival_s);

/// Rules, in order: e-stop, link fault, drive not enabled, fault latched, invalid feedback,
/// missing, future-stamped or stale command (stamp or arrival older than the timeout) -> 0;
/// clamp to min(configured, motor) limit; soft position limits: the velocity envelope (never
/// faster toward a limit than the axis can stop from), no torque pushing past a limit, braking
/// when moving outward near it.
SafetyOutput apply_safety(const AxisSafetyConfig& config, const CommandFreshness& freshness,
                          const SafetyInput& input);

/// The largest motor torque toward the upper soft limit that keeps the axis inside the velocity
/// envelope (issue 20 1.4), given the state and timing of `input`; +infinity without a finite
/// limit or envelope. Mirror the input (q, qd, torques, limit negated) for the lower limit.
double envelope_max_torque_nm(const AxisSafetyConfig& config, double upper_limit_rad,
                              const SafetyInput& input);

/// Host-side fault latch of one axis (issue 20 1.2). A drive fault (Fault or Fault reaction
/// active in the statusword) latches zero torque. It clears only after a reset was requested
/// (while latched) and the drive then reported Operation enabled for `stable_cycles`
/// consecutive cycles: a statusword that flips back to Operation enabled by itself, or
/// flickers, gives no torque.
class FaultLatch {
 public:
  explicit FaultLatch(int stable_cycles = 5) : stable_cycles_(stable_cycles) {}
  /// One cycle's drive state and whether a fault reset is requested; returns latched().
  bool update(DriveState state, bool reset_requested);
  bool latched() const { return latched_; }

 private:
  int stable_cycles_;
  bool latched_ = false;
  bool reset_seen_ = false;
  int enabled_cycles_ = 0;
};

}  // namespace avs::servo
