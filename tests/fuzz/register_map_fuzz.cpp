// libFuzzer target: the register-map parser (parse_register_map_string). Errors are
// ConfigError "map.yaml:line:col: what"; nothing else may escape.
#include "avs/servo/modbus_handle.hpp"
#include "avs/servo/register_map_yaml.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const avs::servo::RegisterMap map =
        avs::servo::parse_register_map_string(avs::fuzz::text_of(data, size), "map.yaml");
    (void)avs::servo::register_map_to_yaml(map);
  } catch (const avs::servo::ConfigError& e) {
    avs::fuzz::expect_located(e, "map.yaml");
  }
  return 0;
}
