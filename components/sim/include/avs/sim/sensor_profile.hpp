// Named sensor profiles (issue 19): `ideal` is the renderer the old figures came from (pinhole
// optics, sharp projector, Gaussian noise, matte paint, steady light, no motion blur);
// `realistic` adds what a real rig has, each effect with a physical unit (values and sources:
// docs/sim.md, "Sensor profiles").
#pragma once

#include <string>
#include <string_view>

#include "avs/sim/simulator.hpp"

namespace avs::sim {

enum class SensorProfile { kIdeal, kRealistic };

/// "ideal" or "realistic"; std::invalid_argument naming the accepted names otherwise.
SensorProfile parse_sensor_profile(std::string_view name);
const char* to_string(SensorProfile profile);

/// Sets everything the profile decides in `config` (effects, Gaussian noise, motion blur) and
/// leaves the rest (geometry, light levels, seed, frame rate) as it is.
void apply_sensor_profile(SensorProfile profile, SimulatorConfig& config);

}  // namespace avs::sim
