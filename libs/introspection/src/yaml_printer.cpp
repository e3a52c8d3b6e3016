// YAML for decoded samples, shaped like `ros2 topic echo` output (PyYAML block style:
// nested maps indented by two, list items "- " at their key's indentation).
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <string>

#include "avs/introspection/cdr_reader.hpp"

namespace avs::introspection {

namespace {

bool looks_like_yaml_keyword_or_number(const std::string& text) {
  // PyYAML's resolver (which `ros2 topic echo` uses): YAML 1.1 booleans without y/n.
  static const std::array<const char*, 12> keywords = {
      "true", "false", "yes", "no", "on", "off", "null", "~", ".nan", ".inf", "-.inf", "..."};
  std::string lower;
  for (const char c : text) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* keyword : keywords) {
    if (lower == keyword) return true;
  }
  double number = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  return error == std::errc() && end == text.data() + text.size();
}

std::string quote_string(const std::string& text) {
  bool control = false;
  for (const char c : text) control |= static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
  if (control) {  // double-quoted with escapes
    std::string out = "\"";
    for (const char c : text) {
      const auto u = static_cast<unsigned char>(c);
      if (c == '"' || c == '\\') {
        out += '\\';
        out += c;
      } else if (c == '\n') {
        out += "\\n";
      } else if (c == '\t') {
        out += "\\t";
      } else if (u < 0x20 || u == 0x7f) {
        static const char* hex = "0123456789abcdef";
        out += "\\x";
        out += hex[u >> 4];
        out += hex[u & 0xf];
      } else {
        out += c;
      }
    }
    return out + "\"";
  }
  const std::string indicators = "-?:,[]{}#&*!|>'\"%@`";
  const bool plain = !text.empty() && indicators.find(text.front()) == std::string::npos &&
                     text.front() != ' ' && text.back() != ' ' &&
                     text.find(": ") == std::string::npos && text.find(" #") == std::string::npos &&
                     text.back() != ':' && !looks_like_yaml_keyword_or_number(text);
  if (plain) return text;
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// Python-repr-like floats, as PyYAML prints them: 1.0, 0.25, 1.0e-05, .nan, .inf.
std::string float_text(double value, bool single_precision) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[64];
  const auto result = single_precision
                          ? std::to_chars(buffer, buffer + sizeof buffer, static_cast<float>(value))
                          : std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  const auto exponent = text.find('e');
  if (text.find('.') == std::string::npos)
    text.insert(exponent == std::string::npos ? text.size() : exponent, ".0");
  return text;
}

class YamlWriter {
 public:
  explicit YamlWriter(const YamlOptions& options) : options_(options) {}

  std::string write(const Value& value) {
    if (value.kind == Value::Kind::kStruct) {
      write_fields(value, 0, /*first_inline=*/false);
    } else {
      write_after_key(value, 0, false);  // a bare scalar or list: "value" / "- item" lines
      if (out_.front() == ' ') out_.erase(0, 1);
      if (out_.front() == '\n') out_.erase(0, 1);
    }
    return std::move(out_);
  }

 private:
  std::string scalar(const Value& value) const {
    switch (value.kind) {
      case Value::Kind::kBool:
        return value.bool_value ? "true" : "false";
      case Value::Kind::kInt:
        return std::to_string(value.int_value);
      case Value::Kind::kUint:
        return std::to_string(value.uint_value);
      case Value::Kind::kFloat:
        return float_text(value.float_value, value.primitive == Primitive::kFloat32);
      case Value::Kind::kString: {
        const auto limit = options_.max_string_length;
        if (limit == 0 || value.string_value.size() <= limit)
          return quote_string(value.string_value);
        return quote_string(value.string_value.substr(0, limit) + "...");
      }
      default:
        return "?";
    }
  }

  bool summarized(const Value& parent, const std::string& field_name) const {
    return options_.summarize_image_data && field_name == "data" &&
           (parent.type_name == "sensor_msgs::msg::dds_::Image_" ||
            parent.type_name == "sensor_msgs::msg::dds_::PointCloud2_");
  }

  void write_fields(const Value& value, std::size_t indent, bool first_inline) {
    if (value.items.empty()) {
      out_ += "{}\n";
      return;
    }
    for (std::size_t i = 0; i < value.items.size(); ++i) {
      if (i > 0 || !first_inline) out_.append(indent, ' ');
      out_ += value.names[i] + ":";
      write_after_key(value.items[i], indent, summarized(value, value.names[i]));
    }
  }

  // Everything after "key:" (or at the top level): " scalar\n", nested map, or list lines.
  void write_after_key(const Value& value, std::size_t indent, bool force_summary) {
    const auto limit = options_.max_list_elements;
    switch (value.kind) {
      case Value::Kind::kStruct:
        if (value.items.empty()) {
          out_ += " {}\n";
        } else {
          out_ += "\n";
          write_fields(value, indent + 2, false);
        }
        return;
      case Value::Kind::kBytes:
        if (force_summary || (limit != 0 && value.bytes.size() > limit)) {
          out_ += " <" + std::to_string(value.bytes.size()) + " bytes>\n";
          return;
        }
        if (value.bytes.empty()) {
          out_ += " []\n";
          return;
        }
        out_ += "\n";
        for (const auto byte : value.bytes)
          out_.append(indent, ' ').append("- " + std::to_string(byte) + "\n");
        return;
      case Value::Kind::kList: {
        if (value.items.empty()) {
          out_ += " []\n";
          return;
        }
        out_ += "\n";
        const auto shown = limit == 0 ? value.items.size() : std::min(limit, value.items.size());
        for (std::size_t i = 0; i < shown; ++i) {
          out_.append(indent, ' ');
          out_ += "- ";
          const auto& item = value.items[i];
          if (item.kind == Value::Kind::kStruct) {
            write_fields(item, indent + 2, /*first_inline=*/true);
          } else {
            out_ += scalar(item) + "\n";
          }
        }
        if (shown < value.items.size()) {
          out_.append(indent, ' ');
          out_ += "- ... (" + std::to_string(value.items.size() - shown) + " more)\n";
        }
        return;
      }
      default:
        out_ += " " + scalar(value) + "\n";
    }
  }

  const YamlOptions& options_;
  std::string out_;
};

}  // namespace

std::string to_yaml(const Value& value, const YamlOptions& options) {
  return YamlWriter(options).write(value);
}

}  // namespace avs::introspection
