// libFuzzer target: the calibration parser (parse_sensor_geometry_yaml) and the writer on
// what it accepts. Errors are std::runtime_error "calibration.yaml:line:col: what".
#include <stdexcept>

#include "avs/decode/calibration_yaml.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const avs::decode::SensorGeometry geometry =
        avs::decode::parse_sensor_geometry_yaml(avs::fuzz::text_of(data, size), "calibration.yaml");
    (void)avs::decode::sensor_geometry_to_yaml(geometry);
  } catch (const std::runtime_error& e) {
    avs::fuzz::expect_located(e, "calibration.yaml");
  }
  return 0;
}
