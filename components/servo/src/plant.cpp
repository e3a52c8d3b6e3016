#include "avs/servo/plant.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace avs::servo {
namespace {

double sign(double v) {
  return (v > 0) - (v < 0);
}

void check_config(const AxisPlantConfig& c) {
  if (!(c.inertia_kgm2 > 0) || !(c.gear_ratio > 0) || !(c.efficiency > 0) ||
      !(c.max_substep_s > 0) || !(c.encoder_counts_per_motor_rev > 0)) {
    throw std::invalid_argument("AxisPlantConfig: inertia_kgm2 (" + std::to_string(c.inertia_kgm2) +
                                "), gear_ratio, efficiency, max_substep_s and encoder counts "
                                "must be positive");
  }
}

}  // namespace

AxisPlantConfig pan_plant_config() {
  return AxisPlantConfig{};
}

AxisPlantConfig tilt_plant_config() {
  AxisPlantConfig c;
  c.inertia_kgm2 = 0.00117;
  c.viscous_nm_s_per_rad = 0.005;
  c.coulomb_nm = 0.07;
  c.max_motor_torque_nm = 0.9555;  // Table 3 (tilt SGMAS-01A)
  return c;
}

AxisPlant::AxisPlant(const AxisPlantConfig& config) : config_(config) {
  check_config(config_);
}

void AxisPlant::reset(double q_rad, double qd_rad_s) {
  state_ = AxisPlantState{};
  state_.q_rad = q_rad;
  state_.qd_rad_s = qd_rad_s;
}

double AxisPlant::max_output_speed_rad_s() const {
  return config_.max_motor_speed_rpm * 2.0 * std::numbers::pi / 60.0 / config_.gear_ratio;
}

double AxisPlant::output_rad_per_count() const {
  return 2.0 * std::numbers::pi / (config_.encoder_counts_per_motor_rev * config_.gear_ratio);
}

std::int32_t AxisPlant::position_counts() const {
  const auto counts = static_cast<std::int64_t>(std::floor(state_.q_rad / output_rad_per_count()));
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(counts));  // wraps like INT32
}

std::int32_t AxisPlant::velocity_counts_per_s() const {
  return static_cast<std::int32_t>(std::trunc(state_.qd_rad_s / output_rad_per_count()));
}

void AxisPlant::step(double dt_s, double motor_torque_cmd_nm) {
  if (!(dt_s > 0)) return;
  const double tau_m =
      std::clamp(motor_torque_cmd_nm, -config_.max_motor_torque_nm, config_.max_motor_torque_nm);
  state_.motor_torque_nm = tau_m;
  const int n = static_cast<int>(std::ceil(dt_s / config_.max_substep_s - 1e-9));
  const double h = dt_s / n;
  for (int i = 0; i < n; ++i) substep(h, tau_m);
}

void AxisPlant::substep(double h, double tau_m) {
  const AxisPlantConfig& c = config_;
  const double drive = c.efficiency * c.gear_ratio * tau_m - c.gravity_nm * std::sin(state_.q_rad);
  double qd = state_.qd_rad_s;
  double net = 0;
  if (std::abs(qd) < c.stiction_velocity_rad_s) {
    // Stiction: at rest the friction holds up to Fc.
    if (std::abs(drive) <= c.coulomb_nm) {
      state_.qd_rad_s = 0;
      state_.qdd_rad_s2 = 0;
      return;
    }
    net = drive - sign(drive) * c.coulomb_nm - c.viscous_nm_s_per_rad * qd;
  } else {
    net = drive - c.viscous_nm_s_per_rad * qd - c.coulomb_nm * sign(qd);
  }
  const double qdd = net / c.inertia_kgm2;
  double qd_next = qd + qdd * h;
  // Friction cannot reverse the motion within a step: stop at zero when it would.
  if (qd != 0 && qd * qd_next < 0 && std::abs(drive) <= c.coulomb_nm) qd_next = 0;
  const double v_max = max_output_speed_rad_s();
  qd_next = std::clamp(qd_next, -v_max, v_max);  // drive speed limit (6000 rpm motor)
  state_.qdd_rad_s2 = (qd_next - qd) / h;
  state_.qd_rad_s = qd_next;
  state_.q_rad += qd_next * h;  // semi-implicit Euler
}

}  // namespace avs::servo
