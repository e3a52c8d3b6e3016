// Reading YAML files with source locations (file:line:col in every error), argument and
// environment substitution, and error collection: the one YAML reader of the graph loader and
// the deployment loader (libs/deploy). Errors are collected, never thrown one at a time.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "avs/graph/graph.hpp"

namespace avs::graph::detail {

/// Collects every error; loading goes on after an error so all of them are reported.
class Diagnostics {
 public:
  /// A message longer than kMaxMessage (a 50 MB name echoed back) is cut, saying how much.
  void error(SourceLocation where, std::string message) {
    if (message.size() > kMaxMessage) {
      const std::size_t cut = message.size() - kMaxMessage;
      message.resize(kMaxMessage);
      message += "... (" + std::to_string(cut) + " more characters)";
    }
    list_.push_back({std::move(where), std::move(message)});
  }
  static constexpr std::size_t kMaxMessage = 2000;
  const std::vector<Diagnostic>& list() const { return list_; }
  std::vector<Diagnostic> take() { return std::move(list_); }
  std::size_t count() const { return list_.size(); }

 private:
  std::vector<Diagnostic> list_;
};

/// One YAML file being read: its name for diagnostics and its argument scope.
struct FileReader {
  std::string file;
  std::map<std::string, std::string> args;  ///< this file's arguments after overrides
  std::vector<std::string> declared_args;   ///< in file order, with or without a value
  std::vector<std::string> failed_args;     ///< declared, and its error already reported
  Diagnostics* diags = nullptr;

  /// 1-based location of `node` (yaml-cpp marks are 0-based); 1:1 when unknown.
  SourceLocation at(const YAML::Node& node) const;
  SourceLocation at(const YAML::Mark& mark) const;
  void error(const YAML::Node& node, std::string message) const {
    diags->error(at(node), std::move(message));
  }

  /// `text` with every `$(arg NAME)` and `$(env NAME [default])` replaced; errors are
  /// reported at `where` and give nullopt.
  std::optional<std::string> substitute(std::string_view text, const SourceLocation& where) const;

  /// The text of a scalar node after substitution (null node: ""); a list or mapping is
  /// an error naming `what` ("container 'x' key 'host'").
  std::optional<std::string> string(const YAML::Node& node, const std::string& what) const;
  std::optional<double> number(const YAML::Node& node, const std::string& what,
                               std::optional<double> min, std::optional<double> max) const;
  std::optional<std::int64_t> integer(const YAML::Node& node, const std::string& what,
                                      std::int64_t min, std::int64_t max) const;
  /// Index of the scalar's text in `choices`.
  std::optional<std::size_t> choice(const YAML::Node& node, const std::string& what,
                                    const std::vector<std::string>& choices) const;
};

struct Entry {
  std::string key;
  YAML::Node key_node;
  YAML::Node value;
};

/// The pairs of mapping `node` in file order. Reports a non-mapping, duplicate keys and
/// keys not in `allowed` (with the closest allowed one), which are left out. `what`
/// names the mapping in messages ("component 'talker'").
std::vector<Entry> map_entries(const FileReader& reader, const YAML::Node& node,
                               const std::string& what, const std::vector<std::string>& allowed);

/// Value of `key` in `entries`, or a null node.
const Entry* find_entry(const std::vector<Entry>& entries, std::string_view key);

/// " (did you mean 'x'?)" for the candidate closest to `word`, or "" if none is close.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

/// "'a', 'b', 'c'".
std::string join_quoted(const std::vector<std::string>& items);

/// Letters, digits and '_', not starting with a digit.
bool is_identifier(std::string_view name);

/// "a list", "a mapping", "a scalar", "nothing".
std::string node_kind(const YAML::Node& node);

/// The first YAML document of `text`, and in `second` where a second one starts, if any.
/// Not YAML::LoadAll: yaml-cpp 0.7's never returns on a ',' where a document may start
/// (`,`, `[1] ,`: it yields null documents without end), so the documents are counted with a
/// bounded parse. Syntax errors throw YAML::Exception.
YAML::Node load_first_document(const std::string& text, std::optional<YAML::Mark>& second);

}  // namespace avs::graph::detail
