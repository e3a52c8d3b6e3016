// Chunk compression (zstd, lz4 frame format) with reusable contexts. Internal to avs::mcap.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"
#include "byte_buffer.hpp"

namespace avs::mcap::detail {

class Compressor {
 public:
  Compressor(Compression compression, int level);
  ~Compressor();
  Compressor(const Compressor&) = delete;
  Compressor& operator=(const Compressor&) = delete;

  /// Replaces `out` with the compressed form of `in` (not called for Compression::none).
  Status compress(std::span<const std::byte> in, ByteBuffer& out);

 private:
  Compression compression_;
  int level_;
  void* zstd_context_ = nullptr;
};

/// Decompresses a chunk's records. `compression` is the Chunk field ("lz4", "zstd"); `out`
/// receives exactly `uncompressed_size` bytes or an error naming `chunk_offset`.
Status decompress(std::string_view compression, std::span<const std::byte> in,
                  std::uint64_t uncompressed_size, std::uint64_t chunk_offset, ByteBuffer& out);

}  // namespace avs::mcap::detail
