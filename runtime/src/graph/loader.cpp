// load_graph(): reads a graph file and its includes, substitutes arguments, and
// validates everything before anything starts. Format: docs/graphs.md.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "avs/runtime/error.hpp"
#include "avs/runtime/topic_name.hpp"
#include "load_state.hpp"

namespace avs::graph {
namespace detail {
namespace {

/// Bounds of what a graph may be (issue 20: a 4000-file include chain overflowed the stack;
/// a huge file ended in a bare std::bad_alloc).
constexpr std::size_t kMaxIncludeDepth = 64;
/// Includes read for one graph, repeats counted: 64 levels each including the next twice is
/// 2^64 reads within the depth limit (found by an audit: 17 such files took 3.7 s, 40 would
/// never finish).
constexpr std::size_t kMaxIncludedFiles = 1024;
constexpr std::uintmax_t kMaxFileBytes = 16u << 20;

namespace fs = std::filesystem;

const std::vector<std::string> top_keys = {"args",  "namespace", "domain_id",
                                           "clock", "include",   "containers"};
const std::vector<std::string> clock_keys = {"source",
                                             "mode",
                                             "real_time_factor",
                                             "master",
                                             "duration_s",
                                             "wait_for_recorders",
                                             "recorder_start_timeout_s"};

/// Argument values handed to a file: from the command line (top-level file) or from the
/// `args:` of an include entry.
struct GivenArgs {
  std::map<std::string, std::string> values;
  std::map<std::string, SourceLocation> where;  ///< empty for the command line
};

bool same_clock(const ClockSpec& a, const ClockSpec& b) {
  return a.source == b.source && a.mode == b.mode && a.real_time_factor == b.real_time_factor &&
         a.master == b.master && a.duration_s == b.duration_s &&
         a.wait_for_recorders == b.wait_for_recorders &&
         a.recorder_start_timeout_s == b.recorder_start_timeout_s;
}

/// The default text of an argument declaration (scalar, or a list written as "[a, b]").
std::optional<std::string> default_text(const FileReader& reader, const YAML::Node& node,
                                        const std::string& what) {
  if (!node.IsSequence()) return reader.string(node, what);
  std::string text = "[";
  for (std::size_t i = 0; i < node.size(); ++i) {
    auto item = reader.string(node[i], what);
    if (!item) return std::nullopt;
    text += (i == 0 ? "" : ", ") + *item;
  }
  return text + "]";
}

/// Fills reader.args from the file's `args:` declarations and the given values.
void read_args(LoadState& state, FileReader& reader, const Entry* args_entry,
               const GivenArgs& given, bool top_level) {
  std::vector<std::string> declared;
  if (args_entry != nullptr) {
    const std::vector<Entry> entries = map_entries(reader, args_entry->value, "'args'", {});
    // All names first, so that a default using an argument declared below it is told so.
    for (const auto& e : entries) {
      if (is_identifier(e.key)) reader.declared_args.push_back(e.key);
    }
    for (const auto& e : entries) {
      const std::string what = "argument '" + e.key + "'";
      if (!is_identifier(e.key)) {
        reader.error(e.key_node, what + ": expected a name of letters, digits and '_'");
        continue;
      }
      declared.push_back(e.key);
      if (auto it = given.values.find(e.key); it != given.values.end()) {
        reader.args[e.key] = it->second;
        continue;
      }
      YAML::Node def = e.value;
      if (e.value.IsMap()) {
        auto fields = map_entries(reader, e.value, what, {"default", "description"});
        const Entry* d = find_entry(fields, "default");
        def.reset(d != nullptr ? d->value : YAML::Node());  // reset: operator= writes through
      }
      if (!def || def.IsNull()) {
        reader.error(e.key_node, what + " has no default and was not given" +
                                     (top_level ? " (add " + e.key + ":=VALUE to the command line)"
                                                : " (give it in the include's 'args')"));
        reader.failed_args.push_back(e.key);
        continue;
      }
      if (auto text = default_text(reader, def, what + " default")) {
        reader.args[e.key] = *text;
      } else {
        reader.failed_args.push_back(e.key);  // default_text reported why
      }
    }
  }
  for (const auto& [name, value] : given.values) {
    if (std::find(declared.begin(), declared.end(), name) != declared.end()) continue;
    std::string message = "argument '" + name + "' ";
    SourceLocation where{reader.file, 1, 1};
    if (auto it = given.where.find(name); it != given.where.end()) {
      where = it->second;
      message += "given by the include is not declared in '" + reader.file + "'";
    } else {
      if (args_entry != nullptr) where = reader.at(args_entry->key_node);
      message +=
          "given on the command line (" + name + ":=" + value + ") is not declared in 'args'";
    }
    message += declared.empty()
                   ? std::string(" (the file declares no args)")
                   : did_you_mean(name, declared) + "; declared: " + join_quoted(declared);
    state.diags.error(where, message);
  }
  if (top_level) state.graph.args = reader.args;
}

std::optional<ClockSpec> read_clock(LoadState& state, const FileReader& reader,
                                    const YAML::Node& node, bool top_level) {
  ClockSpec clock;
  const std::size_t errors_before = state.diags.count();
  for (const auto& e : map_entries(reader, node, "'clock'", clock_keys)) {
    const std::string what = "clock '" + e.key + "'";
    if (e.key == "source") {
      if (auto i = reader.choice(e.value, what, {"wall", "sim"})) {
        clock.source = *i == 0 ? ClockSpec::Source::wall : ClockSpec::Source::sim;
      }
    } else if (e.key == "mode") {
      if (auto i = reader.choice(e.value, what, {"lockstep", "realtime"})) {
        clock.mode = *i == 0 ? ClockSpec::Mode::lockstep : ClockSpec::Mode::realtime;
      }
    } else if (e.key == "real_time_factor") {
      if (auto v = reader.number(e.value, what, 0.001, 1000.0)) clock.real_time_factor = *v;
    } else if (e.key == "master") {
      if (auto v = reader.string(e.value, what)) {
        clock.master = *v;
        if (top_level) state.master_where = reader.at(e.value);
      }
    } else if (e.key == "duration_s") {
      if (auto v = reader.number(e.value, what, 0.0, std::nullopt)) clock.duration_s = *v;
    } else if (e.key == "wait_for_recorders") {
      if (auto i = reader.choice(e.value, what, {"false", "true"}))
        clock.wait_for_recorders = *i == 1;
    } else if (e.key == "recorder_start_timeout_s") {
      if (auto v = reader.number(e.value, what, 0.0, 3600.0)) clock.recorder_start_timeout_s = *v;
    }
  }
  if (state.diags.count() != errors_before) return std::nullopt;
  return clock;
}

void load_file(LoadState& state, const std::string& path, const GivenArgs& given, bool top_level);

void read_includes(LoadState& state, const FileReader& reader, const YAML::Node& node) {
  if (!node.IsSequence()) {
    reader.error(node,
                 "'include': expected a list of {file: PATH, args: {...}}, got " + node_kind(node));
    return;
  }
  for (const auto& item : node) {
    auto fields = map_entries(reader, item, "include entry", {"file", "args"});
    if (!item.IsMap()) continue;
    const Entry* file_entry = find_entry(fields, "file");
    if (file_entry == nullptr) {
      reader.error(item, "include entry: missing required key 'file'");
      continue;
    }
    auto name = reader.string(file_entry->value, "include 'file'");
    if (!name) continue;
    fs::path resolved = fs::path(*name);
    if (resolved.is_relative()) resolved = fs::path(reader.file).parent_path() / resolved;
    resolved = resolved.lexically_normal();
    std::error_code ec;
    if (name->empty() || !fs::is_regular_file(resolved, ec)) {
      reader.error(file_entry->value, "include 'file': file '" + *name +
                                          "' not found (looked for '" + resolved.string() + "')");
      continue;
    }
    const std::string canonical = fs::weakly_canonical(resolved, ec).string();
    auto cycle_start = std::find(state.include_stack.begin(), state.include_stack.end(), canonical);
    if (cycle_start != state.include_stack.end()) {
      std::string chain;
      for (auto it = cycle_start; it != state.include_stack.end(); ++it) {
        chain += fs::path(*it).filename().string() + " -> ";
      }
      reader.error(file_entry->value,
                   "include 'file': include cycle " + chain + resolved.filename().string());
      continue;
    }
    GivenArgs child_args;
    if (const Entry* args = find_entry(fields, "args")) {
      for (const auto& a : map_entries(reader, args->value, "include 'args'", {})) {
        if (auto value = reader.string(a.value, "include argument '" + a.key + "'")) {
          child_args.values[a.key] = *value;
          child_args.where[a.key] = reader.at(a.key_node);
        }
      }
    }
    if (state.include_stack.size() >= kMaxIncludeDepth) {
      reader.error(file_entry->value,
                   "include 'file': includes nested deeper than " +
                       std::to_string(kMaxIncludeDepth) + " files (from " +
                       fs::path(state.include_stack.front()).filename().string() +
                       "); is this include chain intended?");
      continue;
    }
    if (++state.included_files > kMaxIncludedFiles) {
      if (!state.include_budget_reported) {
        reader.error(file_entry->value,
                     "include 'file': more than " + std::to_string(kMaxIncludedFiles) +
                         " includes read for one graph (a file included more than once is "
                         "read each time); is this include structure intended?");
        state.include_budget_reported = true;
      }
      continue;
    }
    state.include_stack.push_back(canonical);
    load_file(state, resolved.string(), child_args, false);
    state.include_stack.pop_back();
  }
}

std::optional<YAML::Node> parse_yaml(LoadState& state, const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    state.diags.error({path, 1, 1}, "cannot open graph file '" + path + "'");
    return std::nullopt;
  }
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (!ec && size > kMaxFileBytes) {
    state.diags.error({path, 1, 1}, "graph file is " + std::to_string(size) +
                                        " bytes, more than the limit of " +
                                        std::to_string(kMaxFileBytes) + " for a graph");
    return std::nullopt;
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    // A second document ('---') is an error, not silently ignored.
    std::optional<YAML::Mark> second;
    const std::string all = text.str();
    YAML::Node document = load_first_document(all, second);
    if (second) {
      const SourceLocation where = second->is_null()
                                       ? SourceLocation{path, 1, 1}
                                       : SourceLocation{path, second->line + 1, second->column + 1};
      const bool comma = !second->is_null() && second->pos >= 0 &&
                         static_cast<std::size_t>(second->pos) < all.size() &&
                         all[static_cast<std::size_t>(second->pos)] == ',';
      state.diags.error(
          where, comma ? "YAML syntax error: ',' outside a flow collection ([...] or {...})"
                       : "a second YAML document in a graph file (after '---'); a graph is one "
                         "document, use 'include' for more files");
      return std::nullopt;
    }
    return document;
  } catch (const YAML::Exception& e) {
    const SourceLocation where = e.mark.is_null()
                                     ? SourceLocation{path, 1, 1}
                                     : SourceLocation{path, e.mark.line + 1, e.mark.column + 1};
    state.diags.error(where, "YAML syntax error: " + e.msg);
    return std::nullopt;
  }
}

void load_file(LoadState& state, const std::string& path, const GivenArgs& given, bool top_level) {
  state.graph.files.push_back(path);
  auto root = parse_yaml(state, path);
  if (!root) return;
  FileReader reader;
  reader.file = path;
  reader.diags = &state.diags;
  if (!root->IsMap()) {
    reader.error(*root,
                 "graph file: expected a mapping with 'containers', got " + node_kind(*root));
    return;
  }
  const auto entries = map_entries(reader, *root, "graph file", top_keys);

  // 1. Arguments first: every other value may use them.
  read_args(state, reader, find_entry(entries, "args"), given, top_level);

  // 2. Graph-wide settings: set by the top-level file; included files may only repeat them.
  if (const Entry* e = find_entry(entries, "namespace")) {
    if (auto ns = reader.string(e->value, "'namespace'")) {
      try {
        runtime::resolve_topic_name(*ns, "x");
        if (top_level) {
          state.graph.ns = *ns;
        } else if (*ns != state.graph.ns) {
          reader.error(e->value, "'namespace': included file says '" + *ns +
                                     "' but the graph uses '" + state.graph.ns +
                                     "'; remove it or make it equal");
        }
      } catch (const runtime::Error& err) {
        reader.error(e->value, std::string("'namespace': ") + err.what() +
                                   "; expected '/' or an absolute name like '/robot1'");
      }
    }
  }
  if (const Entry* e = find_entry(entries, "domain_id")) {
    if (auto id = reader.integer(e->value, "'domain_id'", 0, 232)) {
      if (top_level) {
        state.graph.domain_id = static_cast<int>(*id);
      } else if (*id != state.graph.domain_id) {
        reader.error(e->value, "'domain_id': included file says " + std::to_string(*id) +
                                   " but the graph uses " + std::to_string(state.graph.domain_id) +
                                   "; remove it or make it equal");
      }
    }
  }
  if (const Entry* e = find_entry(entries, "clock")) {
    if (auto clock = read_clock(state, reader, e->value, top_level)) {
      if (top_level) {
        state.graph.clock = *clock;
      } else if (!same_clock(*clock, state.graph.clock)) {
        reader.error(e->key_node,
                     "'clock': included file's clock differs from the graph's; remove it or make "
                     "it equal");
      }
    }
  }

  // 3. Includes and containers, in file order.
  for (const auto& e : entries) {
    if (e.key == "include") read_includes(state, reader, e.value);
    if (e.key == "containers") read_containers(state, reader, e.value);
  }
  if (find_entry(entries, "containers") == nullptr && find_entry(entries, "include") == nullptr) {
    reader.error(*root, "graph file: missing required key 'containers'");
  }
}

/// Checks that need the whole graph: the clock master, and topic types.
void check_graph(LoadState& state) {
  auto& graph = state.graph;
  if (graph.clock.master.empty()) {
    if (!graph.containers.empty()) graph.clock.master = graph.containers.front().name;
  } else if (graph.find_container(graph.clock.master) == nullptr && !state.unnamed_container) {
    std::vector<std::string> names;
    for (const auto& c : graph.containers) names.push_back(c.name);
    state.diags.error(state.master_where.value_or(SourceLocation{graph.file, 1, 1}),
                      "clock 'master': unknown container '" + graph.clock.master + "'" +
                          did_you_mean(graph.clock.master, names) +
                          "; containers: " + join_quoted(names));
  }
  check_topics(state);
}

}  // namespace
}  // namespace detail

LoadResult load_graph(const std::string& file, const std::map<std::string, std::string>& args) {
  detail::LoadState state;
  state.graph.file = file;
  std::error_code ec;
  state.include_stack.push_back(std::filesystem::weakly_canonical(file, ec).string());
  detail::GivenArgs given;
  given.values = args;
  detail::load_file(state, file, given, true);
  detail::check_graph(state);
  LoadResult result;
  result.errors = state.diags.take();
  // Report in reading order: by file (as loaded), then line and column.
  auto file_rank = [&](const std::string& f) {
    const auto& files = state.graph.files;
    return static_cast<std::size_t>(std::find(files.begin(), files.end(), f) - files.begin());
  };
  std::stable_sort(result.errors.begin(), result.errors.end(),
                   [&](const Diagnostic& a, const Diagnostic& b) {
                     const auto ra = file_rank(a.where.file);
                     const auto rb = file_rank(b.where.file);
                     if (ra != rb) return ra < rb;
                     if (a.where.line != b.where.line) return a.where.line < b.where.line;
                     return a.where.column < b.where.column;
                   });
  if (result.errors.empty()) result.graph = std::move(state.graph);
  return result;
}

std::map<std::string, std::string> parse_arg_overrides(const std::vector<std::string>& words,
                                                       std::vector<std::string>* rest) {
  std::map<std::string, std::string> out;
  for (const auto& w : words) {
    const auto pos = w.find(":=");
    if (pos != std::string::npos && pos > 0) {
      out[w.substr(0, pos)] = w.substr(pos + 2);
    } else if (rest != nullptr) {
      rest->push_back(w);
    }
  }
  return out;
}

}  // namespace avs::graph
