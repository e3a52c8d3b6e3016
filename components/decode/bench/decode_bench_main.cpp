// Stand-alone runner for the decode benchmark (the same function `avs bench decode` runs), for
// building without the whole avs program: prints the report rows and the JSON keys.
#include <cstdio>
#include <string>
#include <vector>

#include "avs/bench/report.hpp"

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
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
