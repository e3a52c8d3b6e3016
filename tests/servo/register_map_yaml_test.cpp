#include "avs/servo/register_map_yaml.hpp"

#include <gtest/gtest.h>

#include "avs/servo/modbus_handle.hpp"

namespace avs::servo {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_register_map_string(yaml, "servo.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

TEST(RegisterMapYaml, DefaultMapRoundTrips) {
  const RegisterMap map = default_register_map(1.91, 1.1e-5);
  const RegisterMap parsed = parse_register_map_string(register_map_to_yaml(map), "round trip");
  for (std::size_t i = 0; i < signal_count; ++i) {
    EXPECT_EQ(parsed.specs[i].present, map.specs[i].present);
    EXPECT_EQ(parsed.specs[i].address, map.specs[i].address);
    EXPECT_EQ(parsed.specs[i].width_registers, map.specs[i].width_registers);
    EXPECT_EQ(parsed.specs[i].is_signed, map.specs[i].is_signed);
    EXPECT_EQ(parsed.specs[i].word_order, map.specs[i].word_order);
    EXPECT_DOUBLE_EQ(parsed.specs[i].scale, map.specs[i].scale);
  }
}

constexpr const char* valid_map = R"(word_order: low_first
registers:
  controlword: {address: 0}
  target_torque: {address: 1, signed: true, scale: 0.00191}
  statusword: {address: 4}
  position_actual: {address: 8, size: 32, signed: true, scale: 1.0e-5}
  velocity_actual: {address: 10, size: 32, signed: true, scale: 1.0e-5, word_order: high_first}
)";

TEST(RegisterMapYaml, ParsesSizesOrdersAndTheDefaultOrder) {
  const RegisterMap map = parse_register_map_string(valid_map, "servo.yaml");
  EXPECT_EQ(map[Signal::position_actual].width_registers, 2);
  EXPECT_EQ(map[Signal::position_actual].word_order, WordOrder::low_first);
  EXPECT_EQ(map[Signal::velocity_actual].word_order, WordOrder::high_first);
  EXPECT_DOUBLE_EQ(map[Signal::target_torque].scale, 0.00191);
  EXPECT_FALSE(map.has(Signal::echo_counter));
}

TEST(RegisterMapYaml, UnknownRegisterNameIsOneClearLine) {
  std::string yaml = valid_map;
  yaml += "  torque_demand: {address: 20}\n";
  const std::string error = error_of(yaml);
  EXPECT_NE(error.find("servo.yaml:8:3: unknown register 'torque_demand'"), std::string::npos)
      << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST(RegisterMapYaml, BadWordOrderIsOneClearLine) {
  std::string yaml = valid_map;
  yaml.replace(yaml.find("word_order: high_first"), 22, "word_order: middle");
  const std::string error = error_of(yaml);
  EXPECT_NE(error.find("servo.yaml:7:85: register velocity_actual: bad word_order 'middle'"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

// Found by tests/fuzz (fuzz_register_map): yaml-cpp's "bad conversion" without a file escaped.
TEST(RegisterMapYaml, ListsAndMapsWhereANameBelongsAreLocatedErrors) {
  EXPECT_EQ(error_of("word_order: [high_first]\nregisters: {controlword: {address: 0}}\n"),
            "servo.yaml:1:13: register (default): word_order must be a name");
  EXPECT_EQ(error_of("registers: {[controlword]: {address: 0}}\n"),
            "servo.yaml:1:13: a register name is not a name");
  EXPECT_EQ(error_of("registers: {controlword: {{address: 0}: 1}}\n"),
            "servo.yaml:1:27: register controlword: a key is not a name");
}

TEST(RegisterMapYaml, OtherMistakesNameTheRegister) {
  EXPECT_NE(
      error_of("registers:\n  controlword: {address: 0, size: 24}\n").find("size must be 16 or 32"),
      std::string::npos);
  EXPECT_NE(error_of("registers:\n  controlword: {adress: 0}\n").find("unknown key 'adress'"),
            std::string::npos);
  EXPECT_NE(error_of("registers:\n  controlword: {address: 0}\n").find("required register"),
            std::string::npos);
  EXPECT_THROW(load_register_map("/nonexistent/servo.yaml"), ConfigError);
}

}  // namespace
}  // namespace avs::servo
