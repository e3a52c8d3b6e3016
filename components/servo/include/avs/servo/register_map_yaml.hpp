// YAML adapter for RegisterMap (the core stays free of YAML). Format (docs/servo.md):
//   word_order: high_first            # default for 32-bit registers, optional
//   registers:
//     controlword:     {address: 0}
//     target_torque:   {address: 1, signed: true, scale: 0.00191}
//     position_actual: {address: 8, size: 32, signed: true, word_order: low_first, scale: 1.1e-5}
// Every error is a ConfigError with one line "<source>:<line>:<column>: <what>".
#pragma once

#include <string>
#include <string_view>

#include <yaml-cpp/yaml.h>

#include "avs/servo/register_map.hpp"

namespace avs::servo {

/// `source` names the file or parameter in messages.
RegisterMap parse_register_map(const YAML::Node& node, std::string_view source);
RegisterMap parse_register_map_string(const std::string& yaml_text, std::string_view source);
RegisterMap load_register_map(const std::string& path);
/// The YAML of a register-map file (one map, or `axes:` with one per axis), unparsed.
YAML::Node load_register_map_file(const std::string& path);

/// The inverse, for docs and round trips.
std::string register_map_to_yaml(const RegisterMap& map);

}  // namespace avs::servo
