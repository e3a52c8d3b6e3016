// CRC-32 as MCAP uses it (CRC-32/ISO-HDLC, the zlib/PNG polynomial), through zlib.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace avs::mcap::detail {

/// Continues `crc` (start with 0) over `bytes`.
std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::byte> bytes);
/// The CRC of A followed by B from crc(A), crc(B) and B's length (no pass over the bytes).
std::uint32_t crc32_combine(std::uint32_t crc_a, std::uint32_t crc_b, std::uint64_t length_b);

}  // namespace avs::mcap::detail
