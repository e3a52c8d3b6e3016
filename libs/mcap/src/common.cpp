#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"

namespace avs::mcap {

const char* status_code_name(StatusCode code) {
  switch (code) {
    case StatusCode::ok:
      return "ok";
    case StatusCode::invalid_argument:
      return "invalid argument";
    case StatusCode::io_error:
      return "I/O error";
    case StatusCode::malformed:
      return "malformed";
    case StatusCode::truncated:
      return "truncated";
    case StatusCode::crc_mismatch:
      return "CRC mismatch";
    case StatusCode::unsupported:
      return "unsupported";
    case StatusCode::too_large:
      return "too large";
    case StatusCode::incomplete:
      return "incomplete";
  }
  return "unknown";
}

std::string Status::to_string() const {
  if (ok()) return "ok";
  return std::string(status_code_name(code_)) + ": " + message_;
}

std::string_view compression_field(Compression compression) {
  switch (compression) {
    case Compression::none:
      return "";
    case Compression::lz4:
      return "lz4";
    case Compression::zstd:
      return "zstd";
  }
  return "";
}

std::optional<Compression> parse_compression(std::string_view name) {
  if (name == "none" || name.empty()) return Compression::none;
  if (name == "lz4") return Compression::lz4;
  if (name == "zstd") return Compression::zstd;
  return std::nullopt;
}

}  // namespace avs::mcap
