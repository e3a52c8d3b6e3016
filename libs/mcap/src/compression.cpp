#include "compression.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <string>

#include "serialize.hpp"

namespace avs::mcap::detail {

Compressor::Compressor(Compression compression, int level)
    : compression_(compression), level_(level) {
  if (compression_ == Compression::zstd) zstd_context_ = ZSTD_createCCtx();
}

Compressor::~Compressor() {
  if (zstd_context_ != nullptr) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_context_));
}

Status Compressor::compress(std::span<const std::byte> in, ByteBuffer& out) {
  switch (compression_) {
    case Compression::none:
      return Status(StatusCode::invalid_argument, "compress() called for Compression::none");
    case Compression::zstd: {
      auto* context = static_cast<ZSTD_CCtx*>(zstd_context_);
      if (context == nullptr) return Status(StatusCode::io_error, "ZSTD_createCCtx failed");
      out.resize_uninitialized(ZSTD_compressBound(in.size()));
      std::size_t n =
          ZSTD_compressCCtx(context, out.data(), out.size(), in.data(), in.size(), level_);
      if (ZSTD_isError(n)) {
        return Status(StatusCode::io_error,
                      std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
      }
      out.resize_uninitialized(n);
      return {};
    }
    case Compression::lz4: {
      LZ4F_preferences_t preferences{};
      preferences.compressionLevel = level_;
      preferences.frameInfo.contentSize = in.size();
      out.resize_uninitialized(LZ4F_compressFrameBound(in.size(), &preferences));
      std::size_t n =
          LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &preferences);
      if (LZ4F_isError(n)) {
        return Status(StatusCode::io_error,
                      std::string("lz4 compression failed: ") + LZ4F_getErrorName(n));
      }
      out.resize_uninitialized(n);
      return {};
    }
  }
  return Status(StatusCode::invalid_argument, "unknown compression");
}

namespace {

Status decompress_lz4(std::span<const std::byte> in, std::uint64_t uncompressed_size,
                      const std::string& where, ByteBuffer& out) {
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
    return Status(StatusCode::io_error, where + ": LZ4F_createDecompressionContext failed");
  }
  std::size_t produced = 0;
  std::size_t consumed = 0;
  std::size_t hint = 1;
  while (consumed < in.size()) {
    std::size_t out_n = out.size() - produced;
    std::size_t in_n = in.size() - consumed;
    hint = LZ4F_decompress(context, out.data() + produced, &out_n, in.data() + consumed, &in_n,
                           nullptr);
    if (LZ4F_isError(hint)) {
      std::string name = LZ4F_getErrorName(hint);
      LZ4F_freeDecompressionContext(context);
      return Status(StatusCode::malformed, where + ": lz4 data is corrupt (" + name + ")");
    }
    produced += out_n;
    consumed += in_n;
    if (hint == 0) break;                // frame complete
    if (out_n == 0 && in_n == 0) break;  // no progress: output full
  }
  LZ4F_freeDecompressionContext(context);
  if (hint != 0) {
    return Status(StatusCode::malformed,
                  where + ": lz4 frame incomplete or larger than uncompressed_size " +
                      std::to_string(uncompressed_size));
  }
  if (produced != uncompressed_size) {
    return Status(StatusCode::malformed,
                  where + ": lz4 frame decompressed to " + std::to_string(produced) +
                      " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
  }
  return {};
}

}  // namespace

Status decompress(std::string_view compression, std::span<const std::byte> in,
                  std::uint64_t uncompressed_size, std::uint64_t chunk_offset, ByteBuffer& out) {
  const std::string where = "chunk at offset " + std::to_string(chunk_offset);
  out.resize_uninitialized(static_cast<std::size_t>(uncompressed_size));
  if (compression == "zstd") {
    std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
    if (ZSTD_isError(n)) {
      return Status(StatusCode::malformed,
                    where + ": zstd data is corrupt (" + ZSTD_getErrorName(n) + ")");
    }
    if (n != uncompressed_size) {
      return Status(StatusCode::malformed,
                    where + ": zstd data decompressed to " + std::to_string(n) +
                        " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
    }
    return {};
  }
  if (compression == "lz4") return decompress_lz4(in, uncompressed_size, where, out);
  return Status(StatusCode::unsupported,
                where + ": unknown compression \"" + std::string(compression) + "\"");
}

}  // namespace avs::mcap::detail
