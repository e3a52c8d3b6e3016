// Stand-alone runner for the decode benchmark (the same function `avs bench decode` runs), for
// building without the whole avs program: prints the report rows and the JSON keys (always, so
// --json is accepted and ignored).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "avs/bench/report.hpp"

namespace {

int run(std::vector<std::string> args) {
  args.erase(std::remove(args.begin(), args.end(), "--json"), args.end());
  for (const auto& bench : avs::bench::bench_registry()) {
    if (bench.name != "decode") continue;
    const avs::bench::Report report = bench.run(args);
    std::printf("%s\n", report.title.c_str());
    for (const auto& row : report.rows) {
      std::printf("  %-72s %9.4f %s", row.what.c_str(), row.ours, row.unit.c_str());
      if (!row.peer_name.empty()) {
        std::printf(" | %s %9.3f %s (x%.1f)", row.peer_name.c_str(), row.peer, row.unit.c_str(),
                    row.peer / row.ours);
      }
      std::printf("\n");
    }
    for (const auto& note : report.notes) std::printf("  note: %s\n", note.c_str());
    std::printf("{");
    const char* separator = "";
    for (const auto& [key, value] : report.json) {
      std::printf("%s\"%s\": %.6g", separator, key.c_str(), value);
      separator = ", ";
    }
    std::printf("}\n");
    return 0;
  }
  std::fprintf(stderr, "decode benchmark not registered\n");
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const avs::bench::HelpRequested& help) {
    std::printf("%s\n", help.what());
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "avs_decode_bench_run: %s\n", error.what());
    return 2;
  }
}
