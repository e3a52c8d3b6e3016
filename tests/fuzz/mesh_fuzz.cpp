// libFuzzer target: one mesh reader (load_mesh on a file with the extension named by
// AVS_FUZZ_MESH_EXTENSION: ply, stl or obj). Errors are std::runtime_error naming the file.
#include <stdexcept>

#include "avs/geometry/mesh.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const avs::fuzz::ScratchDir scratch;
  const std::string file =
      scratch.write("mesh." AVS_FUZZ_MESH_EXTENSION, avs::fuzz::text_of(data, size));
  try {
    (void)avs::geometry::load_mesh(file);
  } catch (const std::runtime_error& e) {
    avs::fuzz::expect_located(e, file);
  }
  return 0;
}
