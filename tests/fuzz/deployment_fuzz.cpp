// libFuzzer target: the deployment loader (load_deployment) on one deployment file; the
// scratch folder holds `graph.yaml`, a valid graph it can name. Errors are located
// diagnostics, never an exception, crash or hang.
#include <cstdio>
#include <cstdlib>

#include "avs/deploy/deployment.hpp"
#include "fake_components.hpp"
#include "fuzz_support.hpp"

namespace {

const avs::fuzz::ScratchDir& scratch() {
  static const avs::fuzz::ScratchDir dir;
  static const bool graph = [] {
    dir.write("graph.yaml",
              "containers:\n  - name: vision\n    components:\n      - type: fake_camera\n"
              "        name: cam\n  - name: head\n    components:\n"
              "      - type: fake_talker\n        name: talker\n");
    return true;
  }();
  (void)graph;
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  avs::fuzz::register_fake_components();
  const std::string file = scratch().write("deployment.yaml", avs::fuzz::text_of(data, size));
  const avs::deploy::LoadResult result = avs::deploy::load_deployment(file, {}, false);
  for (const avs::graph::Diagnostic& d : result.errors) {
    if (d.where.file.empty() || d.where.line < 1 || d.message.empty()) {
      std::fprintf(stderr, "diagnostic without location: %s\n", d.str().c_str());
      std::abort();
    }
  }
  return 0;
}
