// Little-endian encoding of MCAP fields (spec § Serialization) and a bounds-checked Cursor
// for decoding them. Internal to avs::mcap.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"
#include "byte_buffer.hpp"

namespace avs::mcap::detail {

void put_u8(ByteBuffer& out, std::uint8_t v);
void put_u16(ByteBuffer& out, std::uint16_t v);
void put_u32(ByteBuffer& out, std::uint32_t v);
void put_u64(ByteBuffer& out, std::uint64_t v);
void put_string(ByteBuffer& out, std::string_view s);   ///< u32 length + bytes
void put_map(ByteBuffer& out, const KeyValueMap& map);  ///< u32 byte length + entries
void put_map(ByteBuffer& out, const std::map<std::uint16_t, std::uint64_t>& map);
/// Writes opcode + content length; returns the position of the length for patch_u64().
std::size_t begin_record(ByteBuffer& out, Opcode op);
void end_record(ByteBuffer& out, std::size_t length_position);  ///< patches the length
void write_u64_at(std::byte* at, std::uint64_t v);
void write_u32_at(std::byte* at, std::uint32_t v);

std::uint16_t load_u16(const std::byte* p);
std::uint32_t load_u32(const std::byte* p);
std::uint64_t load_u64(const std::byte* p);

/// Record builders shared by the writer and repair.
void put_schema_record(ByteBuffer& out, const Schema& schema);
void put_channel_record(ByteBuffer& out, const Channel& channel);
void put_chunk_index_record(ByteBuffer& out, const ChunkIndex& index);
void put_statistics_record(ByteBuffer& out, const Statistics& stats);
void put_metadata_record(ByteBuffer& out, const Metadata& metadata);
void put_metadata_index_record(ByteBuffer& out, const MetadataIndex& index);

/// Reads fields from `bytes`, whose first byte lies at file offset `base_offset` (or, inside
/// a chunk, the uncompressed offset; `where` says which). The first failure sticks: later
/// reads return zero values and status() names the offset of the field that did not fit.
class Cursor {
 public:
  Cursor(std::span<const std::byte> bytes, std::uint64_t base_offset, std::string where)
      : bytes_(bytes), base_(base_offset), where_(std::move(where)) {}

  std::uint8_t u8();
  std::uint16_t u16();
  std::uint32_t u32();
  std::uint64_t u64();
  std::string string(const char* field);
  /// u32-length-prefixed bytes, as a view into the input.
  std::span<const std::byte> bytes32(const char* field);
  /// u64-length-prefixed bytes, as a view into the input.
  std::span<const std::byte> bytes64(const char* field);
  KeyValueMap string_map(const char* field);
  std::map<std::uint16_t, std::uint64_t> u16_u64_map(const char* field);
  std::span<const std::byte> rest();

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  std::uint64_t offset() const { return base_ + pos_; }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  void fail(StatusCode code, const std::string& what);

 private:
  bool need(std::size_t n, const char* field);
  std::span<const std::byte> bytes_;
  std::uint64_t base_;
  std::string where_;
  std::size_t pos_ = 0;
  Status status_;
};

std::string hex(std::uint64_t v);

}  // namespace avs::mcap::detail
