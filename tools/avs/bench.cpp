// avs bench [NAME [--json] [ARGS...]]: runs a registered benchmark and prints ours beside
// the peer measured in the same run, or one JSON object with unit-carrying keys.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "avs/bench/report.hpp"
#include "commands.hpp"

namespace avs::cli {

namespace {

#ifdef AVS_HAVE_BENCHMARKS
constexpr bool kHaveBenchmarks = true;
#else
constexpr bool kHaveBenchmarks = false;
#endif
constexpr const char* kNoBenchmarks =
    "this avs was built without benchmarks (AVS_BUILD_BENCHMARKS=OFF, as in the demo build); "
    "configure with -DAVS_BUILD_BENCHMARKS=ON to build them";

void print_table(const bench::Report& report) {
  std::printf("%s\n\n", report.title.c_str());
  std::printf("%-48s %12s   %-34s %12s %9s\n", "measure", "avs", "peer", "peer", "ratio");
  for (const auto& row : report.rows) {
    if (row.peer_name.empty()) {
      std::printf("%-48s %9.4f %-2s\n", row.what.c_str(), row.ours, row.unit.c_str());
    } else {
      std::printf("%-48s %9.4f %-2s   %-34s %9.4f %-2s %8.1fx\n", row.what.c_str(), row.ours,
                  row.unit.c_str(), row.peer_name.c_str(), row.peer, row.unit.c_str(),
                  row.ours > 0 ? row.peer / row.ours : 0.0);
    }
  }
  for (const auto& note : report.notes) std::printf("\n%s", note.c_str());
  std::printf("\n");
}

void print_json(const bench::Report& report) {
  std::printf("{");
  bool first = true;
  for (const auto& [key, value] : report.json) {
    // JSON has no NaN or infinity: a figure that could not be measured is null.
    if (std::isfinite(value)) {
      std::printf("%s\"%s\": %.6g", first ? "" : ", ", key.c_str(), value);
    } else {
      std::printf("%s\"%s\": null", first ? "" : ", ", key.c_str());
    }
    first = false;
  }
  std::printf("}\n");
}

}  // namespace

void add_bench_command(Command& app) {
  auto* cmd = app.add_subcommand("bench", "Benchmarks against a peer measured in the same run");
  static std::string name;
  static bool json = false;
  static bool help = false;
  cmd->add_option("name", name, "benchmark name (omit to list them)");
  // Our own help flag: `avs bench NAME --help` is the benchmark's help (its options with ranges
  // and defaults), `avs bench --help` this one.
  cmd->own_help_flag(help, "this help; after NAME: the benchmark's options");
  cmd->add_flag("--json", json, "print one JSON object (keys carry units)");
  // Everything after the name goes to the benchmark in the order given (--model FILE, ...).
  cmd->prefix_command();
  cmd->footer((kHaveBenchmarks ? std::string() : std::string("Note: ") + kNoBenchmarks + ".\n") +
              "Arguments after NAME go to the benchmark in order, e.g. avs bench matching "
              "--model my.ply --json");
  cmd->callback([cmd] {
    if (help && name.empty()) {
      std::cout << cmd->help_text();
      return;
    }
    if (!kHaveBenchmarks) {
      std::cerr << "avs bench: " << kNoBenchmarks << "\n";
      exit_status() = name.empty() ? 0 : 2;
      return;
    }
    std::vector<std::string> args;
    for (const auto& word : cmd->remaining()) {
      if (word == "--json") {
        json = true;
      } else {
        args.push_back(word);
      }
    }
    if (name.empty()) {
      for (const auto& b : bench::bench_registry()) {
        std::printf("%-12s %s\n", b.name.c_str(), b.description.c_str());
      }
      return;
    }
    if (help) args.push_back("--help");
    for (const auto& b : bench::bench_registry()) {
      if (b.name != name) continue;
      try {
        const bench::Report report = b.run(args);
        json ? print_json(report) : print_table(report);
      } catch (const bench::HelpRequested& h) {
        std::cout << "avs bench " << b.name << ": " << b.description << "\n"
                  << h.what()
                  << "  --json                      print one JSON object (keys carry units)\n";
      }
      return;
    }
    std::cerr << "avs bench: no benchmark '" << name << "' (run `avs bench` to list them)\n";
    exit_status() = 2;
  });
}

}  // namespace avs::cli
