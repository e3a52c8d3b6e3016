// Small text helpers every file format of avs shares: where a YAML node sits in its file, and
// escaping for XML and HTML. Written once (issue 13).
#pragma once

#include <string>
#include <string_view>

#include <yaml-cpp/mark.h>

namespace avs::runtime {

/// "source:line:column" of a yaml-cpp mark (0-based in yaml-cpp, 1-based here), or "source"
/// when the mark is unknown (a node made in code, a missing key).
inline std::string yaml_location(std::string_view source, const YAML::Mark& mark) {
  std::string out(source);
  if (mark.is_null() || mark.line < 0) return out;
  return out + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

/// `text` with & < > " escaped, for XML attributes and text and for HTML.
inline std::string escape_markup(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace avs::runtime
