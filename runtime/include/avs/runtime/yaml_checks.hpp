// Checks the YAML file formats of avs share (calibration files, capture indexes, board-pose
// files): an error naming the node's file, line and column, unknown keys, number lists.
// Written once (issue 14); include only where yaml-cpp is already used.
#pragma once

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "avs/runtime/text.hpp"

namespace avs::runtime {

/// Throws std::runtime_error "source:line:column: what".
[[noreturn]] inline void yaml_fail(const std::string& source, const YAML::Node& node,
                                   const std::string& what) {
  throw std::runtime_error(yaml_location(source, node.Mark()) + ": " + what);
}

/// yaml-cpp's own complaint (operator[] on a scalar, a list read as a string, ...) as
/// "source:line:column: what": for a parser's outermost catch, so that no message without
/// its file reaches the user (issue 20: found by tests/fuzz).
inline std::string yaml_error_message(const std::string& source, const YAML::Exception& error) {
  return yaml_location(source, error.mark) + ": " + error.msg;
}

/// `text` parsed as one YAML document; a syntax error throws std::runtime_error
/// "source:line:column: what yaml-cpp says".
inline YAML::Node yaml_parse(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(yaml_location(source, e.mark) + ": " + e.msg);
  }
}

/// The file at `path` parsed as YAML; `what` names it when it cannot be opened
/// ("path: cannot open register map").
inline YAML::Node yaml_load_file(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open " + what);
  std::stringstream text;
  text << in.rdbuf();
  return yaml_parse(text.str(), path);
}

/// `node` must be a map whose keys are all in `allowed`; `section` names it in errors.
inline void yaml_check_keys(const std::string& source, const YAML::Node& node,
                            const std::set<std::string>& allowed, const std::string& section) {
  if (!node.IsMap()) yaml_fail(source, node, section + " must be a map");
  for (const auto& entry : node) {
    if (!entry.first.IsScalar())
      yaml_fail(source, entry.first, "a key in " + section + " is not a name");
    const std::string& key = entry.first.Scalar();
    if (!allowed.count(key)) {
      yaml_fail(source, entry.first, "unknown key '" + key + "' in " + section);
    }
  }
}

/// `node` must be a list of exactly `size` numbers; `key` names it in errors.
inline std::vector<double> yaml_numbers(const std::string& source, const YAML::Node& node,
                                        std::size_t size, const std::string& key) {
  if (!node.IsSequence() || node.size() != size) {
    yaml_fail(source, node, "'" + key + "' must be a list of " + std::to_string(size) + " numbers");
  }
  std::vector<double> values;
  for (const auto& item : node) {
    try {
      values.push_back(item.as<double>());
    } catch (const YAML::Exception&) {
      yaml_fail(source, item, "'" + key + "' must hold numbers");
    }
  }
  return values;
}

}  // namespace avs::runtime
