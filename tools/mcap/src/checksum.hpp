// CRC-32 as MCAP uses it (CRC-32/ISO-HDLC, the zlib/PNG polynomial), through zlib.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace avs::mcap::detail {

/// Continues `crc` (start with 0) over `bytes`.
std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::byte> bytes);

}  // namespace avs::mcap::detail
