#include "flash_images.hpp"

// Built where the projector library is (the demo-only build may leave it out).
#if __has_include("avs/projector/pattern_sequence.hpp")

#include <cstdio>
#include <fstream>

#include "avs/projector/pattern_sequence.hpp"

namespace avs::cli {

int write_flash_images(const std::vector<std::vector<std::uint8_t>>& patterns,
                       const std::vector<std::string>& labels, const std::string& label_header,
                       int width, int height, int first_flash_image,
                       const std::filesystem::path& dir) {
  const auto images = projector::pack_flash_images(patterns, width, height);
  for (std::size_t i = 0; i < images.size(); ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "flash_image_%02zu.bmp", i);
    const std::vector<std::uint8_t> bmp = projector::encode_bmp24(images[i]);
    std::ofstream out(dir / name, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bmp.data()), static_cast<std::streamsize>(bmp.size()));
    if (!out) return -1;
  }
  projector::SequenceConfig sequence;
  sequence.pattern_count = static_cast<int>(patterns.size());
  sequence.first_flash_image = first_flash_image;
  std::ofstream lut(dir / "lut.csv");
  lut << "entry," << label_header
      << ",flash_file,flash_image_index,pattern_number,bit_plane,"
         "bit_depth,trigger,buffer_swap,trigger_out_previous,lut_bytes\n";
  const auto entries = projector::pattern_lut(sequence);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const projector::PatternEntry& e = entries[k];
    const projector::FlashSlot slot = projector::flash_slot(static_cast<int>(k));
    const auto b = e.encode();
    char bytes[16];
    std::snprintf(bytes, sizeof bytes, "%02X %02X %02X", b[0], b[1], b[2]);
    lut << k << ',' << labels[k] << ',' << "flash_image_" << (slot.image < 10 ? "0" : "")
        << slot.image << ".bmp," << first_flash_image + slot.image << ',' << e.pattern_number << ','
        << projector::plane_name(e.pattern_number) << ',' << e.bit_depth << ','
        << (e.trigger == projector::TriggerType::kInternal ? "internal" : "external") << ','
        << (e.buffer_swap ? 1 : 0) << ',' << (e.trigger_out_previous ? 1 : 0) << ',' << bytes
        << '\n';
  }
  return lut ? static_cast<int>(images.size()) : -1;
}

}  // namespace avs::cli

#endif
