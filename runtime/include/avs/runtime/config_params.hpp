// A component's parameters bound to the fields of its core's Config: the spec's default of each
// parameter is that field's value in a default-constructed Config, and make() fills a Config
// from the parameter values. One default, written once, in the core (issue 13): no second list
// in the component, no make_config() copying field by field.
//
//   static const runtime::ConfigParams<TrackerConfig>& params() {
//     static const auto p = runtime::ConfigParams<TrackerConfig>()
//         .integer("frames_to_track", AVS_FIELD(frames_to_track), 1, 1e5, "", "...")
//         .vector("kp_nm_per_rad", AVS_FIELD(law.kp_nm_per_rad), "N m/rad", "K_p (pan, tilt)");
//     return p;
//   }
#pragma once

#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "avs/runtime/parameters.hpp"

/// Accessor of a (nested) Config field for ConfigParams, usable on const and non-const Configs.
#define AVS_FIELD(path)        \
  [](auto& config_) -> auto& { \
    return config_.path;       \
  }

namespace avs::runtime {

template <class Config>
class ConfigParams {
 public:
  template <class Get>
  ConfigParams&& real(std::string name, Get get, std::optional<double> min,
                      std::optional<double> max, std::string unit, std::string description) && {
    const Config d{};
    add(
        ParamSpec::real(name, as_decimal(get(d)), min, max, std::move(unit),
                        std::move(description)),
        [get, name](const ParameterValues& v, Config& c) {
          using T = std::remove_cvref_t<decltype(get(c))>;
          get(c) = static_cast<T>(v.get<double>(name));
        },
        [get](const Config& c) -> ParamValue { return static_cast<double>(get(c)); });
    return std::move(*this);
  }

  template <class Get>
  ConfigParams&& integer(std::string name, Get get, std::optional<double> min,
                         std::optional<double> max, std::string unit, std::string description) && {
    const Config d{};
    add(
        ParamSpec::integer(name, static_cast<std::int64_t>(get(d)), min, max, std::move(unit),
                           std::move(description)),
        [get, name](const ParameterValues& v, Config& c) {
          using T = std::remove_cvref_t<decltype(get(c))>;
          get(c) = static_cast<T>(v.get<std::int64_t>(name));
        },
        [get](const Config& c) -> ParamValue { return static_cast<std::int64_t>(get(c)); });
    return std::move(*this);
  }

  template <class Get>
  ConfigParams&& boolean(std::string name, Get get, std::string description) && {
    const Config d{};
    add(
        ParamSpec::boolean(name, static_cast<bool>(get(d)), std::move(description)),
        [get, name](const ParameterValues& v, Config& c) { get(c) = v.get<bool>(name); },
        [get](const Config& c) -> ParamValue { return static_cast<bool>(get(c)); });
    return std::move(*this);
  }

  template <class Get>
  ConfigParams&& string(std::string name, Get get, std::string description,
                        std::vector<std::string> choices = {}) && {
    const Config d{};
    add(
        ParamSpec::string(name, get(d), std::move(description), std::move(choices)),
        [get, name](const ParameterValues& v, Config& c) { get(c) = v.get<std::string>(name); },
        [get](const Config& c) -> ParamValue { return std::string(get(c)); });
    return std::move(*this);
  }

  /// An enum field as a string parameter with one name per value.
  template <class Get, class Enum>
  ConfigParams&& choice(std::string name, Get get,
                        std::vector<std::pair<std::string, Enum>> options,
                        std::string description) && {
    const Config d{};
    std::vector<std::string> names;
    std::string default_name;
    for (const auto& [option, value] : options) {
      names.push_back(option);
      if (value == get(d)) default_name = option;
    }
    if (default_name.empty()) throw Error("parameter '" + name + "': the default has no name");
    add(
        ParamSpec::string(name, default_name, std::move(description), names),
        [get, name, options](const ParameterValues& v, Config& c) {
          const std::string chosen = v.get<std::string>(name);
          for (const auto& [option, value] : options) {
            if (option == chosen) get(c) = value;
          }
        },
        [get, options](const Config& c) -> ParamValue {
          for (const auto& [option, value] : options) {
            if (value == get(c)) return option;
          }
          return std::string("<unnamed>");
        });
    return std::move(*this);
  }

  /// A fixed-size vector field (Eigen::Vector2d/3d, std::array) as a real_list of exactly its
  /// size (each element in [min, max] when given); another size is refused by make() with the
  /// parameter's name.
  template <class Get>
  ConfigParams&& vector(std::string name, Get get, std::string unit, std::string description,
                        std::optional<double> min = std::nullopt,
                        std::optional<double> max = std::nullopt) && {
    const Config d{};
    ParamSpec spec =
        ParamSpec::real_list(name, to_list(get(d)), std::move(unit), std::move(description));
    spec.min = min;
    spec.max = max;
    add(
        std::move(spec),
        [get, name](const ParameterValues& v, Config& c) {
          const auto list = v.get<std::vector<double>>(name);
          auto& field = get(c);
          const auto size = static_cast<std::size_t>(field.size());
          if (list.size() != size) {
            throw Error("parameter '" + name + "' needs " + std::to_string(size) + " values, got " +
                        std::to_string(list.size()));
          }
          for (std::size_t i = 0; i < size; ++i) {
            field[static_cast<decltype(field.size())>(i)] =
                static_cast<std::remove_cvref_t<decltype(field[0])>>(list[i]);
          }
        },
        [get](const Config& c) -> ParamValue { return to_list(get(c)); });
    return std::move(*this);
  }

  /// Marks the parameter added last as dynamic (ParamSpec::dynamic): changeable while the
  /// graph runs; the component re-makes its Config (make()) in on_parameters_changed.
  ConfigParams&& live() && {
    if (specs_.empty()) throw Error("ConfigParams::live() before any parameter");
    specs_.back().dynamic = true;
    return std::move(*this);
  }

  const std::vector<ParamSpec>& specs() const { return specs_; }

  /// A float field's default as the decimal it was written as (0.05f -> 0.05, not
  /// 0.05000000074505806); it converts back to the same float.
  template <class T>
  static double as_decimal(T value) {
    if constexpr (std::is_same_v<T, float>) {
      char text[32];
      const auto end = std::to_chars(text, text + sizeof text, value).ptr;
      return std::strtod(std::string(text, end).c_str(), nullptr);
    } else {
      return static_cast<double>(value);
    }
  }

  /// specs() followed by `more` (the component's own parameters, not the core's).
  std::vector<ParamSpec> specs_with(std::vector<ParamSpec> more) const {
    std::vector<ParamSpec> all = specs_;
    for (auto& spec : more) all.push_back(std::move(spec));
    return all;
  }

  /// A default Config with every bound field set from `values`.
  Config make(const ParameterValues& values) const {
    Config c{};
    for (const auto& apply : apply_) apply(values, c);
    return c;
  }

  /// The parameters whose spec default, applied to a Config, does not give the field of a
  /// default-constructed Config (lossy conversions, an enum without its name). Tests.
  std::vector<std::string> default_mismatches() const {
    ParameterValues defaults;
    for (const auto& spec : specs_) defaults.set(spec.name, spec.default_value);
    const Config made = make(defaults);
    const Config d{};
    std::vector<std::string> out;
    for (std::size_t i = 0; i < specs_.size(); ++i) {
      if (!(extract_[i](made) == extract_[i](d))) out.push_back(specs_[i].name);
    }
    return out;
  }

 private:
  template <class Vec>
  static std::vector<double> to_list(const Vec& v) {
    std::vector<double> out;
    for (std::size_t i = 0; i < static_cast<std::size_t>(v.size()); ++i) {
      out.push_back(static_cast<double>(v[static_cast<decltype(v.size())>(i)]));
    }
    return out;
  }

  void add(ParamSpec spec, std::function<void(const ParameterValues&, Config&)> apply,
           std::function<ParamValue(const Config&)> extract) {
    specs_.push_back(std::move(spec));
    apply_.push_back(std::move(apply));
    extract_.push_back(std::move(extract));
  }

  std::vector<ParamSpec> specs_;
  std::vector<std::function<void(const ParameterValues&, Config&)>> apply_;
  std::vector<std::function<ParamValue(const Config&)>> extract_;
};

}  // namespace avs::runtime
