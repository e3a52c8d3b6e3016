// libFuzzer target: the graph loader (load_graph) on one graph file. A bad graph gives
// located diagnostics, never an exception, crash or hang. The scratch folder also holds
// `sub.yaml`, a valid graph, for inputs that include it.
#include <cstdio>
#include <cstdlib>

#include "avs/graph/graph.hpp"
#include "fake_components.hpp"
#include "fuzz_support.hpp"

namespace {

const avs::fuzz::ScratchDir& scratch() {
  static const avs::fuzz::ScratchDir dir;
  static const bool sub = [] {
    dir.write("sub.yaml",
              "containers:\n  - name: sub\n    components:\n      - type: fake_camera\n"
              "        name: cam\n");
    return true;
  }();
  (void)sub;
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  avs::fuzz::register_fake_components();
  const std::string file = scratch().write("graph.yaml", avs::fuzz::text_of(data, size));
  const avs::graph::LoadResult result = avs::graph::load_graph(file, {{"rate", "5"}});
  for (const avs::graph::Diagnostic& d : result.errors) {
    if (d.where.file.empty() || d.where.line < 1 || d.message.empty()) {
      std::fprintf(stderr, "diagnostic without location: %s\n", d.str().c_str());
      std::abort();
    }
  }
  return 0;
}
