// Typed parameter specs: factories, printing, and the range/choice check used by the
// graph loader before anything starts.
#include "avs/runtime/parameters.hpp"

#include <cctype>
#include <charconv>
#include <cmath>

namespace avs::runtime {
namespace {

/// " in [0.1, 10000] Hz", " >= 0 m", "" (no bounds, no unit).
std::string bounds_and_unit(const ParamSpec& spec) {
  std::string r = range_text(spec.min, spec.max);
  if (!spec.unit.empty()) r += " " + spec.unit;
  return r;
}

bool in_range(const ParamSpec& spec, double v) {
  if (!std::isfinite(v)) return false;
  if (spec.min && v < *spec.min) return false;
  if (spec.max && v > *spec.max) return false;
  return true;
}

/// How a value is shown after "got": strings quoted so that '' and ' x' are visible.
std::string got_text(const ParamValue& value) {
  if (std::holds_alternative<std::string>(value)) {
    return "'" + std::get<std::string>(value) + "'";
  }
  return to_string(value);
}

std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_int(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  std::int64_t v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// "[1, 2.5]" (or "1, 2.5") as numbers; nullopt when an element is not one.
std::optional<std::vector<double>> parse_list(std::string_view text) {
  text = trim(text);
  if (text.size() >= 2 && text.front() == '[' && text.back() == ']') {
    text = trim(text.substr(1, text.size() - 2));
  }
  std::vector<double> values;
  while (!text.empty()) {
    const auto comma = text.find(',');
    const auto item = trim(text.substr(0, comma));
    const auto v = parse_double(item);
    if (!v) return std::nullopt;
    values.push_back(*v);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return values;
}

/// Would YAML read `s` back as this very string (not a number, bool, null, list, ...)?
bool plain_yaml_string(const std::string& s) {
  if (s.empty() || s == "true" || s == "false" || s == "null" || s == "~") return false;
  if (parse_double(s) || s.front() == ' ' || s.back() == ' ') return false;
  for (const char c : s) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/' || c == '.' ||
          c == '-' || c == ' ')) {
      return false;
    }
  }
  return s.front() != '-';
}

std::string join_quoted(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) {
    if (!out.empty()) out += ", ";
    out += "'" + s + "'";
  }
  return out;
}

}  // namespace

ParamValue parse_param_text(ParamType type, std::string_view text) {
  switch (type) {
    case ParamType::boolean:  // only true/false: "yes", "on", "1" are typos more often than not
      if (text == "true") return true;
      if (text == "false") return false;
      break;
    case ParamType::integer:
      if (auto i = parse_int(text)) return *i;
      break;
    case ParamType::real:
      if (auto i = parse_int(text)) return static_cast<double>(*i);
      if (auto d = parse_double(text)) return *d;
      break;
    case ParamType::real_list:
      if (auto list = parse_list(text)) return std::move(*list);
      break;
    case ParamType::string:
      break;
  }
  return std::string(text);
}

std::string to_yaml_text(const ParamValue& value) {
  if (const auto* s = std::get_if<std::string>(&value)) {
    if (plain_yaml_string(*s)) return *s;
    std::string quoted = "'";
    for (const char c : *s) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    return quoted + "'";
  }
  if (const auto* d = std::get_if<double>(&value)) {
    // A whole number keeps its point so that YAML (and a reader of the file) sees a float.
    std::string text = format_number(*d);
    if (text.find_first_of(".eEni") == std::string::npos) text += ".0";
    return text;
  }
  return to_string(value);
}

ParamSpec ParamSpec::live() && {
  dynamic = true;
  return std::move(*this);
}

std::string format_number(double v) {
  // Whole numbers as integers ("10000000", not "1e+07"), as a person writes them.
  // Up to 2^53, where a double still holds every integer (a range's 1e15 bound included).
  if (std::isfinite(v) && v == std::floor(v) && std::abs(v) <= 9007199254740992.0) {
    return std::to_string(static_cast<long long>(v));
  }
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  if (ec != std::errc()) return std::to_string(v);
  return std::string(buf, end);
}

std::string range_text(std::optional<double> min, std::optional<double> max) {
  if (min && max) return " in [" + format_number(*min) + ", " + format_number(*max) + "]";
  if (min) return " >= " + format_number(*min);
  if (max) return " <= " + format_number(*max);
  return "";
}

std::string to_string(ParamType type) {
  // ROS 2's names (rcl_interfaces ParameterType, as `ros2 param describe` and `avs param`
  // print them): one vocabulary in `avs components` and `avs param`.
  switch (type) {
    case ParamType::boolean:
      return "boolean";
    case ParamType::integer:
      return "integer";
    case ParamType::real:
      return "double";
    case ParamType::string:
      return "string";
    case ParamType::real_list:
      return "double array";
  }
  return "unknown";
}

std::string to_string(const ParamValue& value) {
  struct Printer {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(std::int64_t i) const { return std::to_string(i); }
    std::string operator()(double d) const { return format_number(d); }
    std::string operator()(const std::string& s) const { return s; }
    std::string operator()(const std::vector<double>& list) const {
      std::string out = "[";
      for (std::size_t i = 0; i < list.size(); ++i) {
        if (i != 0) out += ", ";
        out += format_number(list[i]);
      }
      return out + "]";
    }
  };
  return std::visit(Printer{}, value);
}

ParamType type_of(const ParamValue& value) {
  switch (value.index()) {
    case 0:
      return ParamType::boolean;
    case 1:
      return ParamType::integer;
    case 2:
      return ParamType::real;
    case 3:
      return ParamType::string;
    default:
      return ParamType::real_list;
  }
}

ParamSpec ParamSpec::boolean(std::string name, bool def, std::string description) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = ParamType::boolean;
  s.default_value = def;
  s.description = std::move(description);
  return s;
}

ParamSpec ParamSpec::integer(std::string name, std::int64_t def, std::optional<double> min,
                             std::optional<double> max, std::string unit, std::string description) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = ParamType::integer;
  s.default_value = def;
  s.min = min;
  s.max = max;
  s.unit = std::move(unit);
  s.description = std::move(description);
  return s;
}

ParamSpec ParamSpec::real(std::string name, double def, std::optional<double> min,
                          std::optional<double> max, std::string unit, std::string description) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = ParamType::real;
  s.default_value = def;
  s.min = min;
  s.max = max;
  s.unit = std::move(unit);
  s.description = std::move(description);
  return s;
}

ParamSpec ParamSpec::string(std::string name, std::string def, std::string description,
                            std::vector<std::string> choices) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = ParamType::string;
  s.default_value = std::move(def);
  s.choices = std::move(choices);
  s.description = std::move(description);
  return s;
}

ParamSpec ParamSpec::real_list(std::string name, std::vector<double> def, std::string unit,
                               std::string description) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = ParamType::real_list;
  s.default_value = std::move(def);
  s.unit = std::move(unit);
  s.description = std::move(description);
  return s;
}

std::string ParamSpec::check(const ParamValue& value) const {
  const ParamType got = type_of(value);
  switch (type) {
    case ParamType::boolean:
      if (got != ParamType::boolean) return "expected true or false, got " + got_text(value);
      return {};
    case ParamType::integer: {
      const std::string expected = "expected an integer" + bounds_and_unit(*this);
      if (got != ParamType::integer) return expected + ", got " + got_text(value);
      if (!in_range(*this, static_cast<double>(std::get<std::int64_t>(value)))) {
        return expected + ", got " + got_text(value);
      }
      return {};
    }
    case ParamType::real: {
      const std::string expected = "expected a number" + bounds_and_unit(*this);
      double v = 0.0;
      if (got == ParamType::real) {
        v = std::get<double>(value);
      } else if (got == ParamType::integer) {  // integers are accepted for numbers
        v = static_cast<double>(std::get<std::int64_t>(value));
      } else {
        return expected + ", got " + got_text(value);
      }
      if (!in_range(*this, v)) return expected + ", got " + got_text(value);
      return {};
    }
    case ParamType::string: {
      if (got != ParamType::string) {
        if (!choices.empty()) {
          return "expected one of " + join_quoted(choices) + ", got " + got_text(value);
        }
        return "expected a string, got " + got_text(value);
      }
      if (choices.empty()) return {};
      for (const auto& c : choices) {
        if (c == std::get<std::string>(value)) return {};
      }
      return "expected one of " + join_quoted(choices) + ", got " + got_text(value);
    }
    case ParamType::real_list: {
      const std::string expected = "expected a list of numbers" + bounds_and_unit(*this);
      if (got != ParamType::real_list) return expected + ", got " + got_text(value);
      const auto& list = std::get<std::vector<double>>(value);
      for (std::size_t i = 0; i < list.size(); ++i) {
        if (!in_range(*this, list[i])) {
          return expected + ", got " + format_number(list[i]) + " at index " + std::to_string(i);
        }
      }
      return {};
    }
  }
  return "unknown parameter type";
}

}  // namespace avs::runtime
