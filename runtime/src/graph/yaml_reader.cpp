#include "avs/graph/yaml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <yaml-cpp/eventhandler.h>

#include "avs/runtime/parameters.hpp"

namespace avs::graph::detail {
namespace {

/// Keeps only where the last document parsed starts: its root node, else its '---'.
class DocumentStarts : public YAML::EventHandler {
 public:
  std::optional<YAML::Mark> last;
  void OnDocumentStart(const YAML::Mark& mark) override {
    last = mark;
    root_seen_ = false;
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    node(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    node(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    node(mark);
  }
  void OnMapEnd() override {}

 private:
  void node(const YAML::Mark& mark) {
    if (!root_seen_) last = mark;
    root_seen_ = true;
  }
  bool root_seen_ = false;
};

using runtime::range_text;

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0u : 1u)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

SourceLocation FileReader::at(const YAML::Mark& mark) const {
  if (mark.is_null()) return {file, 1, 1};
  return {file, mark.line + 1, mark.column + 1};
}

SourceLocation FileReader::at(const YAML::Node& node) const {
  return at(node.Mark());
}

std::optional<std::string> FileReader::substitute(std::string_view text,
                                                  const SourceLocation& where) const {
  std::string out;
  std::size_t pos = 0;
  bool ok = true;
  while (pos < text.size()) {
    const auto start = text.find("$(", pos);
    if (start == std::string_view::npos) {
      out.append(text.substr(pos));
      break;
    }
    out.append(text.substr(pos, start - pos));
    const auto end = text.find(')', start);
    if (end == std::string_view::npos) {
      diags->error(where, "unterminated substitution '" + std::string(text.substr(start)) +
                              "': expected '$(arg NAME)' or '$(env NAME)'");
      return std::nullopt;
    }
    // Words inside the parentheses: command and its operands.
    std::vector<std::string> words;
    std::string word;
    for (char c : text.substr(start + 2, end - start - 2)) {
      if (c == ' ' || c == '\t') {
        if (!word.empty()) words.push_back(std::move(word));
        word.clear();
      } else {
        word += c;
      }
    }
    if (!word.empty()) words.push_back(std::move(word));
    const std::string whole(text.substr(start, end - start + 1));
    if (words.size() == 2 && words[0] == "arg") {
      auto it = args.find(words[1]);
      const bool declared =
          std::find(declared_args.begin(), declared_args.end(), words[1]) != declared_args.end();
      const bool failed =
          std::find(failed_args.begin(), failed_args.end(), words[1]) != failed_args.end();
      if (it != args.end()) {
        out += it->second;
      } else if (failed) {
        ok = false;  // declared without a usable value: already reported at the declaration
      } else if (declared) {
        // Declared, but its value is being worked out (`a: $(arg a)`) or comes later.
        diags->error(where, "argument '" + words[1] + "' in '" + whole +
                                "' has no value here: a default may use only the arguments "
                                "declared above it, never itself");
        ok = false;
      } else {
        diags->error(where,
                     "undefined argument '" + words[1] + "' in '" + whole + "'" +
                         (declared_args.empty() ? std::string(" (no args declared in this file)")
                                                : did_you_mean(words[1], declared_args) +
                                                      "; declared: " + join_quoted(declared_args)));
        ok = false;
      }
    } else if ((words.size() == 2 || words.size() == 3) && words[0] == "env") {
      const char* value = std::getenv(words[1].c_str());
      if (value != nullptr) {
        out += value;
      } else if (words.size() == 3) {
        out += words[2];
      } else {
        diags->error(where, "environment variable '" + words[1] + "' in '" + whole +
                                "' is not set (give a default: '$(env " + words[1] + " VALUE)')");
        ok = false;
      }
    } else {
      diags->error(where, "bad substitution '" + whole +
                              "': expected '$(arg NAME)', '$(env NAME)' or '$(env NAME DEFAULT)'");
      ok = false;
    }
    pos = end + 1;
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<std::string> FileReader::string(const YAML::Node& node,
                                              const std::string& what) const {
  if (!node || node.IsNull()) return std::string();
  if (!node.IsScalar()) {
    error(node, what + ": expected a single value, got " + node_kind(node));
    return std::nullopt;
  }
  return substitute(node.Scalar(), at(node));
}

std::optional<double> FileReader::number(const YAML::Node& node, const std::string& what,
                                         std::optional<double> min,
                                         std::optional<double> max) const {
  auto text = string(node, what);
  if (!text) return std::nullopt;
  std::string_view s = *text;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  const bool parsed = ec == std::errc() && end == s.data() + s.size() && !s.empty();
  if (!parsed || !std::isfinite(v) || (min && v < *min) || (max && v > *max)) {
    error(node, what + ": expected a number" + range_text(min, max) + ", got '" + *text + "'");
    return std::nullopt;
  }
  return v;
}

std::optional<std::int64_t> FileReader::integer(const YAML::Node& node, const std::string& what,
                                                std::int64_t min, std::int64_t max) const {
  auto text = string(node, what);
  if (!text) return std::nullopt;
  std::string_view s = *text;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  std::int64_t v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  const bool parsed = ec == std::errc() && end == s.data() + s.size() && !s.empty();
  if (!parsed || v < min || v > max) {
    error(node, what + ": expected an integer" +
                    range_text(static_cast<double>(min), static_cast<double>(max)) + ", got '" +
                    *text + "'");
    return std::nullopt;
  }
  return v;
}

std::optional<std::size_t> FileReader::choice(const YAML::Node& node, const std::string& what,
                                              const std::vector<std::string>& choices) const {
  auto text = string(node, what);
  if (!text) return std::nullopt;
  for (std::size_t i = 0; i < choices.size(); ++i) {
    if (choices[i] == *text) return i;
  }
  error(node, what + ": expected one of " + join_quoted(choices) + ", got '" + *text + "'");
  return std::nullopt;
}

std::vector<Entry> map_entries(const FileReader& reader, const YAML::Node& node,
                               const std::string& what, const std::vector<std::string>& allowed) {
  std::vector<Entry> out;
  if (!node || node.IsNull()) return out;
  if (!node.IsMap()) {
    reader.error(node, what + ": expected a mapping, got " + node_kind(node));
    return out;
  }
  for (const auto& pair : node) {
    const YAML::Node key = pair.first;
    if (!key.IsScalar()) {
      reader.error(key, what + ": expected a plain key, got " + node_kind(key));
      continue;
    }
    const std::string name = key.Scalar();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      reader.error(key, what + ": unknown key '" + name + "'" + did_you_mean(name, allowed) +
                            "; expected one of " + join_quoted(allowed));
      continue;
    }
    if (find_entry(out, name) != nullptr) {
      reader.error(key, what + ": duplicate key '" + name + "'");
      continue;
    }
    out.push_back({name, key, pair.second});
  }
  return out;
}

const Entry* find_entry(const std::vector<Entry>& entries, std::string_view key) {
  for (const auto& e : entries) {
    if (e.key == key) return &e;
  }
  return nullptr;
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  // Closest by edit distance relative to length; at most half the longer name differs.
  const std::string* best = nullptr;
  double best_score = 0.0;
  for (const auto& c : candidates) {
    const std::size_t longer = std::max(word.size(), c.size());
    const std::size_t d = edit_distance(word, c);
    if (d > std::max<std::size_t>(2, longer / 2) || d >= longer) continue;
    const double score = static_cast<double>(d) / static_cast<double>(longer);
    if (best == nullptr || score < best_score) {
      best = &c;
      best_score = score;
    }
  }
  return best == nullptr ? "" : " (did you mean '" + *best + "'?)";
}

std::string join_quoted(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) {
    if (!out.empty()) out += ", ";
    out += "'" + s + "'";
  }
  return out;
}

bool is_identifier(std::string_view name) {
  if (name.empty() || (name[0] >= '0' && name[0] <= '9')) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

std::string node_kind(const YAML::Node& node) {
  if (!node || node.IsNull()) return "nothing";
  if (node.IsSequence()) return node.size() == 0 ? "an empty list" : "a list";
  if (node.IsMap()) return "a mapping";
  return "'" + node.Scalar() + "'";
}

YAML::Node load_first_document(const std::string& text, std::optional<YAML::Mark>& second) {
  second.reset();
  YAML::Node first = YAML::Load(text);  // parses the first document only
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentStarts starts;
  if (parser.HandleNextDocument(starts)) {
    starts.last.reset();
    if (parser.HandleNextDocument(starts)) second = starts.last.value_or(YAML::Mark::null_mark());
  }
  return first;
}

}  // namespace avs::graph::detail
