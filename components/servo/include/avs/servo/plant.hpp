// Pan/tilt head plant (paper Table 3; reference section 4): per axis, output side,
//   J q'' = eta N tau_m - b q' - Fc sign(q') [- gravity_nm sin(q)]
// integrated with semi-implicit Euler sub-steps (>= 10 kHz by default), with the motor torque
// limit, the motor speed limit (6000 rpm) and encoder quantisation.
#pragma once

#include <cstdint>

namespace avs::servo {

struct AxisPlantConfig {
  double inertia_kgm2 = 0.00598;        ///< J_eq at the output (reference 4: pan, assumed)
  double gear_ratio = 4.2;              ///< N (Table 3)
  double efficiency = 0.95;             ///< eta, belt drive (assumption, no datasheet)
  double viscous_nm_s_per_rad = 0.02;   ///< b (assumption, reference 4)
  double coulomb_nm = 0.4;              ///< Fc (assumption, reference 4)
  double gravity_nm = 0.0;              ///< m g l of an unbalanced axis (tilt: ~0.10, optional)
  double max_motor_torque_nm = 5.73;    ///< Table 3 (pan SGMAS-06A)
  double max_motor_speed_rpm = 6000.0;  ///< Table 3
  double encoder_counts_per_motor_rev = 131072.0;  ///< 17-bit encoder (assumption)
  double max_substep_s = 1e-4;                     ///< integration step bound (10 kHz)
  double stiction_velocity_rad_s = 1e-4;           ///< |q'| below this counts as at rest
};

AxisPlantConfig pan_plant_config();   ///< Table 3 pan + reference 4 assumptions
AxisPlantConfig tilt_plant_config();  ///< Table 3 tilt + reference 4 assumptions

struct AxisPlantState {
  double q_rad = 0;
  double qd_rad_s = 0;
  double qdd_rad_s2 = 0;       ///< of the last sub-step
  double motor_torque_nm = 0;  ///< applied (after the limit)
};

class AxisPlant {
 public:
  explicit AxisPlant(const AxisPlantConfig& config = pan_plant_config());

  /// Advances by dt_s holding the motor torque command (clamped to the motor limit).
  void step(double dt_s, double motor_torque_cmd_nm);

  const AxisPlantState& state() const { return state_; }
  const AxisPlantConfig& config() const { return config_; }
  void reset(double q_rad, double qd_rad_s = 0);

  double max_output_speed_rad_s() const;
  double output_rad_per_count() const;
  /// Position as the encoder reports it: INT32 counts (motor side), wrapping.
  std::int32_t position_counts() const;
  /// Velocity in counts/s, truncated to INT32.
  std::int32_t velocity_counts_per_s() const;

 private:
  void substep(double h_s, double tau_m);

  AxisPlantConfig config_;
  AxisPlantState state_;
};

/// The two axes of the head (q1 = pan, q2 = tilt, paper Figure 3).
struct HeadPlant {
  AxisPlant pan{pan_plant_config()};
  AxisPlant tilt{tilt_plant_config()};
  void step(double dt_s, double pan_torque_nm, double tilt_torque_nm) {
    pan.step(dt_s, pan_torque_nm);
    tilt.step(dt_s, tilt_torque_nm);
  }
};

}  // namespace avs::servo
