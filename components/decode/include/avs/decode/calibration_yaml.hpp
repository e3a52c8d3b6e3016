// Calibration file adapter (yaml-cpp): SensorGeometry <-> YAML. Kept out of avs_decode_core.
//
//   camera:    {width: 512, height: 512, fx: 628.8, fy: 628.8, cx: 255.5, cy: 255.5,
//               distortion: [k1, k2, p1, p2, k3]}   # or 8: ..., k4, k5, k6 (rational)
//   projector: {width: 912, height: 1140, fx: 1094.4, ...same keys...}
//   R_projector_camera: [r00, r01, r02, r10, ..., r22]   # row-major, p_proj = R p_cam + t
//   t_projector_camera_m: [x, y, z]
//   code_layout: {bit_count: 9, code_count: 265, rows_per_code: 4, first_row: 40}
//
// Every key is optional and defaults to default_sensor_geometry(); unknown keys are errors.
#pragma once

#include <string>

#include "avs/decode/sensor_geometry.hpp"

namespace avs::decode {

/// Throws std::runtime_error naming the file and line on any error.
SensorGeometry load_sensor_geometry_yaml(const std::string& path);
/// `source_name` is used in error messages.
SensorGeometry parse_sensor_geometry_yaml(const std::string& text,
                                          const std::string& source_name = "<string>");
std::string sensor_geometry_to_yaml(const SensorGeometry& geometry);

}  // namespace avs::decode
