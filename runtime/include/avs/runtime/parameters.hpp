// Typed component parameters: declared statically with defaults, ranges and units,
// validated from YAML before anything starts, read by the component at run time.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "avs/runtime/error.hpp"

namespace avs::runtime {

enum class ParamType { boolean, integer, real, string, real_list };

using ParamValue = std::variant<bool, std::int64_t, double, std::string, std::vector<double>>;

std::string to_string(ParamType type);
std::string to_string(const ParamValue& value);
ParamType type_of(const ParamValue& value);

/// Shortest text that reads back as the same double ("0.1", "1e-06"); whole numbers as
/// integers ("10000", "10000000").
std::string format_number(double v);
/// " in [0.1, 10000]", " >= 0", " <= 5" or "" (no bounds): the one way ranges are shown.
std::string range_text(std::optional<double> min, std::optional<double> max);

/// One declared parameter.
struct ParamSpec {
  std::string name;
  ParamType type = ParamType::real;
  ParamValue default_value;
  std::optional<double> min;  ///< inclusive; numbers (and each list element) only
  std::optional<double> max;  ///< inclusive
  std::vector<std::string> choices;  ///< allowed values for strings, empty = any
  std::string unit;                  ///< "Hz", "m", "rad", "" for none
  std::string description;
  /// Changeable while the graph runs (`avs param set`, ROS 2 set_parameters): the component
  /// applies a change between two callbacks (Component::on_parameters_changed). False: read
  /// when the component starts (sizes, ports, files); a change needs a restart.
  bool dynamic = false;

  static ParamSpec boolean(std::string name, bool def, std::string description);
  static ParamSpec integer(std::string name, std::int64_t def, std::optional<double> min,
                           std::optional<double> max, std::string unit, std::string description);
  static ParamSpec real(std::string name, double def, std::optional<double> min,
                        std::optional<double> max, std::string unit, std::string description);
  static ParamSpec string(std::string name, std::string def, std::string description,
                          std::vector<std::string> choices = {});
  static ParamSpec real_list(std::string name, std::vector<double> def, std::string unit,
                             std::string description);

  /// This spec, marked dynamic: `ParamSpec::real(...).live()`.
  ParamSpec live() &&;

  /// Empty when `value` is acceptable; otherwise what was expected, e.g.
  /// "expected a number in [0.1, 10000] Hz, got 0".
  std::string check(const ParamValue& value) const;
};

/// The value `text` means for a parameter of `type`, as a YAML scalar or flow list says it
/// ("30", "0.5", "true", "[1, 2.5]", "rolling"): the one reading of parameter text, shared by
/// the graph loader and `avs param set`. Text that is not of the type comes back as a string
/// value, so that ParamSpec::check() says what was expected.
ParamValue parse_param_text(ParamType type, std::string_view text);

/// The value as YAML writes it: numbers and booleans plain, strings quoted when YAML would
/// read them otherwise (`avs param dump`), lists in flow style.
std::string to_yaml_text(const ParamValue& value);

/// Values of all declared parameters of one component instance, defaults filled in.
class ParameterValues {
 public:
  void set(const std::string& name, ParamValue value) { values_[name] = std::move(value); }
  bool contains(const std::string& name) const { return values_.count(name) != 0; }
  const std::map<std::string, ParamValue>& all() const { return values_; }

  template <class T>
  T get(const std::string& name) const {
    auto it = values_.find(name);
    if (it == values_.end()) throw Error("parameter '" + name + "' was not declared");
    if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::uint32_t>) {
      return static_cast<T>(std::get<std::int64_t>(it->second));
    } else if constexpr (std::is_same_v<T, float>) {
      return static_cast<float>(std::get<double>(it->second));
    } else {
      if (!std::holds_alternative<T>(it->second)) {
        throw Error("parameter '" + name + "' is a " + to_string(type_of(it->second)));
      }
      return std::get<T>(it->second);
    }
  }

 private:
  std::map<std::string, ParamValue> values_;
};

}  // namespace avs::runtime
