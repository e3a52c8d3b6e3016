#include "avs/servo/register_map_yaml.hpp"

#include <sstream>

#include "avs/runtime/yaml_checks.hpp"
#include "avs/servo/modbus_handle.hpp"

namespace avs::servo {
namespace {

[[noreturn]] void fail(std::string_view source, const YAML::Node& at, const std::string& what) {
  throw ConfigError(
      runtime::yaml_location(source, at.IsDefined() ? at.Mark() : YAML::Mark::null_mark()) + ": " +
      what);
}

std::string known_signals() {
  std::string out;
  for (std::size_t i = 0; i < signal_count; ++i) {
    if (i) out += ", ";
    out += signal_name(static_cast<Signal>(i));
  }
  return out;
}

WordOrder parse_word_order(const YAML::Node& node, std::string_view source,
                           const std::string& register_name) {
  if (!node.IsScalar())
    fail(source, node, "register " + register_name + ": word_order must be a name");
  const std::string& text = node.Scalar();
  if (text == "high_first") return WordOrder::high_first;
  if (text == "low_first") return WordOrder::low_first;
  fail(source, node,
       "register " + register_name + ": bad word_order '" + text +
           "' (expected high_first or low_first)");
}

RegisterSpec parse_spec(const YAML::Node& node, std::string_view source, const std::string& name,
                        WordOrder default_order) {
  if (!node.IsMap()) fail(source, node, "register " + name + ": expected a map {address: N, ...}");
  RegisterSpec spec;
  spec.present = true;
  spec.word_order = default_order;
  bool have_address = false;
  for (const auto& kv : node) {
    if (!kv.first.IsScalar()) fail(source, kv.first, "register " + name + ": a key is not a name");
    const std::string& key = kv.first.Scalar();
    const YAML::Node& value = kv.second;
    try {
      if (key == "address") {
        const int a = value.as<int>();
        if (a < 0 || a > 0xFFFF) fail(source, value, "register " + name + ": address out of range");
        spec.address = static_cast<std::uint16_t>(a);
        have_address = true;
      } else if (key == "size") {
        const int bits = value.as<int>();
        if (bits != 16 && bits != 32) {
          fail(source, value,
               "register " + name + ": size must be 16 or 32, got " + std::to_string(bits));
        }
        spec.width_registers = static_cast<std::uint8_t>(bits / 16);
      } else if (key == "signed") {
        spec.is_signed = value.as<bool>();
      } else if (key == "scale") {
        spec.scale = value.as<double>();
      } else if (key == "word_order") {
        spec.word_order = parse_word_order(value, source, name);
      } else {
        fail(source, kv.first,
             "register " + name + ": unknown key '" + key +
                 "' (expected address, size, signed, scale, word_order)");
      }
    } catch (const YAML::BadConversion&) {
      fail(source, value, "register " + name + ": bad value for '" + key + "'");
    }
  }
  if (!have_address) fail(source, node, "register " + name + ": missing address");
  return spec;
}

RegisterMap parse_map(const YAML::Node& root, std::string_view source) {
  if (!root.IsMap()) fail(source, root, "register map: expected a map with 'registers'");
  WordOrder default_order = WordOrder::high_first;
  if (root["word_order"]) default_order = parse_word_order(root["word_order"], source, "(default)");
  const YAML::Node registers = root["registers"];
  if (!registers || !registers.IsMap()) fail(source, root, "register map: missing 'registers' map");
  RegisterMap map;
  for (const auto& kv : registers) {
    if (!kv.first.IsScalar()) fail(source, kv.first, "a register name is not a name");
    const std::string& name = kv.first.Scalar();
    const std::optional<Signal> signal = signal_from_name(name);
    if (!signal) {
      fail(source, kv.first, "unknown register '" + name + "' (known: " + known_signals() + ")");
    }
    map[*signal] = parse_spec(kv.second, source, name, default_order);
  }
  try {
    validate(map);
  } catch (const std::invalid_argument& e) {
    fail(source, registers, e.what());
  }
  return map;
}

}  // namespace

RegisterMap parse_register_map(const YAML::Node& root, std::string_view source) {
  try {
    return parse_map(root, source);
  } catch (const YAML::Exception& e) {
    throw ConfigError(runtime::yaml_error_message(std::string(source), e));
  }
}

RegisterMap parse_register_map_string(const std::string& yaml_text, std::string_view source) {
  YAML::Node root;
  try {
    root = runtime::yaml_parse(yaml_text, std::string(source));
  } catch (const std::runtime_error& e) {
    throw ConfigError(e.what());
  }
  return parse_register_map(root, source);
}

YAML::Node load_register_map_file(const std::string& path) {
  try {
    return runtime::yaml_load_file(path, "register map");
  } catch (const std::runtime_error& e) {
    throw ConfigError(e.what());  // the servo's configuration errors have one type
  }
}

RegisterMap load_register_map(const std::string& path) {
  return parse_register_map(load_register_map_file(path), path);
}

std::string register_map_to_yaml(const RegisterMap& map) {
  std::ostringstream out;
  out.precision(17);
  out << "registers:\n";
  for (std::size_t i = 0; i < signal_count; ++i) {
    const RegisterSpec& s = map.specs[i];
    if (!s.present) continue;
    out << "  " << signal_name(static_cast<Signal>(i)) << ": {address: " << s.address
        << ", size: " << 16 * s.width_registers << ", signed: " << (s.is_signed ? "true" : "false")
        << ", scale: " << s.scale;
    if (s.width_registers == 2) out << ", word_order: " << to_string(s.word_order);
    out << "}\n";
  }
  return out.str();
}

}  // namespace avs::servo
