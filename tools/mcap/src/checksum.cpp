#include "checksum.hpp"

#include <zlib.h>

namespace avs::mcap::detail {

std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::byte> bytes) {
  return static_cast<std::uint32_t>(
      crc32_z(crc, reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

}  // namespace avs::mcap::detail
