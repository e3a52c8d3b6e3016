// The one shape every `avs bench NAME` shares: rows with ours beside a peer measured in
// the same run and their ratio; `--json` prints `json` (keys carry units, e.g.
// "avs_update_ms", "speedup_vs_opencv") as one object. Benchmarks register themselves
// with AVS_REGISTER_BENCH in a component library.
#pragma once

#include <exception>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace avs::bench {

struct Row {
  std::string what;       ///< "rolling update + triangulation, 512x512"
  std::string unit;       ///< "ms"
  double ours = 0;        ///< median
  std::string peer_name;  ///< "OpenCV 4.6 GrayCodePattern", empty when no peer
  double peer = 0;        ///< median of the peer, same inputs, same run
};

struct Report {
  std::string title;
  std::vector<Row> rows;
  std::map<std::string, double> json;  ///< stable keys with units
  std::vector<std::string> notes;      ///< printed under the table
};

/// args: the words after `avs bench NAME` (e.g. "--model", "ken.ply"); `--json` is handled
/// by the caller.
using BenchFunction = std::function<Report(const std::vector<std::string>& args)>;

struct RegisteredBench {
  std::string name;
  std::string description;
  BenchFunction run;
};

std::vector<RegisteredBench>& bench_registry();

/// A benchmark's arguments as words, "--key=value" split into "--key" and "value" and a lone
/// "--" dropped: `avs bench` hands unknown options over separately from positional words, so
/// "--key value" may arrive out of order and benchmarks document "--key=value".
inline std::vector<std::string> option_words(const std::vector<std::string>& args) {
  std::vector<std::string> words;
  for (const auto& w : args) {
    if (w == "--") continue;
    const auto eq = w.find('=');
    if (w.rfind("--", 0) == 0 && eq != std::string::npos) {
      words.push_back(w.substr(0, eq));
      words.push_back(w.substr(eq + 1));
    } else {
      words.push_back(w);
    }
  }
  return words;
}

/// Thrown by Options::finish() when `--help` (or `-h`) was given and the benchmark did not
/// answer it itself: what() is the list of the options it asked for, with ranges and defaults.
class HelpRequested : public std::exception {
 public:
  explicit HelpRequested(std::string text) : text_(std::move(text)) {}
  const char* what() const noexcept override { return text_.c_str(); }

 private:
  std::string text_;
};

/// A benchmark's options read with their ranges: numbers must be finite, whole where an integer
/// is asked for, and in range, or std::invalid_argument says which benchmark, option and range
/// ("avs bench servo: --rate wants a number in [1, 100000], got 'abc'"), never a bare "stod".
/// Values come as "--key value" or "--key=value" (option_words()); `flags` take no value;
/// finish() refuses options no one asked for, and answers `--help` / `-h` (always flags) with
/// the options asked for (HelpRequested).
class Options {
 public:
  Options(std::string bench, const std::vector<std::string>& args,
          const std::vector<std::string>& flags = {});

  /// Whether the flag (one of the constructor's `flags`) was given.
  bool flag(const std::string& key);
  double number(const std::string& key, double fallback, double min, double max);
  long long integer(const std::string& key, long long fallback, long long min, long long max);
  std::string text(const std::string& key, std::string fallback);
  /// Throws HelpRequested for an unanswered --help, std::invalid_argument for an option that
  /// none of number(), integer(), text(), flag() asked for.
  void finish() const;

 private:
  /// The value given for `key` (nullptr: not given); marks it used.
  const std::string* value(const std::string& key);
  [[noreturn]] void refuse(const std::string& key, const std::string& wanted,
                           const std::string& got) const;

  std::string bench_;
  std::map<std::string, std::string> given_;
  std::map<std::string, bool> used_;
  std::vector<std::string> asked_;  ///< every key asked for, in order (for finish()'s message)
  std::vector<std::string> help_;   ///< "--key  what it takes (default)", in the order asked
};

/// The 1-, 5- and 15-minute load averages as /proc/loadavg gives them ("0.52 0.61 0.70"),
/// printed beside every wall-clock figure; empty when unreadable.
inline std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  if (!(in >> a >> b >> c)) return "";
  return a + " " + b + " " + c;
}

inline bool register_bench(std::string name, std::string description, BenchFunction run) {
  bench_registry().push_back({std::move(name), std::move(description), std::move(run)});
  return true;
}

}  // namespace avs::bench

#define AVS_REGISTER_BENCH(ident, name, description, fn)            \
  [[maybe_unused]] static const bool avs_bench_registered_##ident = \
      ::avs::bench::register_bench(name, description, fn)
