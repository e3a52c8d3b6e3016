#include "serialize.hpp"

#include <cstdio>
#include <cstring>

namespace avs::mcap::detail {

namespace {

template <typename T>
void put_le(ByteBuffer& out, T v) {
  unsigned char b[sizeof(T)];
  for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<unsigned char>(v >> (8 * i));
  out.append(b, sizeof(T));
}

template <typename T>
T load_le(const std::byte* p) {
  T v = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(static_cast<T>(p[i]) << (8 * i));
  return v;
}

}  // namespace

void put_u8(ByteBuffer& out, std::uint8_t v) {
  out.append(&v, 1);
}
void put_u16(ByteBuffer& out, std::uint16_t v) {
  put_le(out, v);
}
void put_u32(ByteBuffer& out, std::uint32_t v) {
  put_le(out, v);
}
void put_u64(ByteBuffer& out, std::uint64_t v) {
  put_le(out, v);
}

void put_string(ByteBuffer& out, std::string_view s) {
  put_u32(out, static_cast<std::uint32_t>(s.size()));
  out.append(s.data(), s.size());
}

void put_map(ByteBuffer& out, const KeyValueMap& map) {
  std::size_t length_at = out.size();
  put_u32(out, 0);
  for (const auto& [key, value] : map) {
    put_string(out, key);
    put_string(out, value);
  }
  write_u32_at(out.data() + length_at, static_cast<std::uint32_t>(out.size() - length_at - 4));
}

void put_map(ByteBuffer& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  put_u32(out, static_cast<std::uint32_t>(map.size() * 10));
  for (const auto& [key, value] : map) {
    put_u16(out, key);
    put_u64(out, value);
  }
}

std::size_t begin_record(ByteBuffer& out, Opcode op) {
  put_u8(out, static_cast<std::uint8_t>(op));
  std::size_t at = out.size();
  put_u64(out, 0);
  return at;
}

void end_record(ByteBuffer& out, std::size_t length_position) {
  write_u64_at(out.data() + length_position, out.size() - length_position - 8);
}

void write_u64_at(std::byte* at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) at[i] = static_cast<std::byte>(v >> (8 * i));
}
void write_u32_at(std::byte* at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) at[i] = static_cast<std::byte>(v >> (8 * i));
}

std::uint16_t load_u16(const std::byte* p) {
  return load_le<std::uint16_t>(p);
}
std::uint32_t load_u32(const std::byte* p) {
  return load_le<std::uint32_t>(p);
}
std::uint64_t load_u64(const std::byte* p) {
  return load_le<std::uint64_t>(p);
}

void put_schema_record(ByteBuffer& out, const Schema& schema) {
  std::size_t at = begin_record(out, Opcode::schema);
  put_u16(out, schema.id);
  put_string(out, schema.name);
  put_string(out, schema.encoding);
  put_string(out, schema.data);
  end_record(out, at);
}

void put_channel_record(ByteBuffer& out, const Channel& channel) {
  std::size_t at = begin_record(out, Opcode::channel);
  put_u16(out, channel.id);
  put_u16(out, channel.schema_id);
  put_string(out, channel.topic);
  put_string(out, channel.message_encoding);
  put_map(out, channel.metadata);
  end_record(out, at);
}

void put_chunk_index_record(ByteBuffer& out, const ChunkIndex& index) {
  std::size_t at = begin_record(out, Opcode::chunk_index);
  put_u64(out, index.message_start_time);
  put_u64(out, index.message_end_time);
  put_u64(out, index.chunk_start_offset);
  put_u64(out, index.chunk_length);
  put_map(out, index.message_index_offsets);
  put_u64(out, index.message_index_length);
  put_string(out, index.compression);
  put_u64(out, index.compressed_size);
  put_u64(out, index.uncompressed_size);
  end_record(out, at);
}

void put_statistics_record(ByteBuffer& out, const Statistics& stats) {
  std::size_t at = begin_record(out, Opcode::statistics);
  put_u64(out, stats.message_count);
  put_u16(out, stats.schema_count);
  put_u32(out, stats.channel_count);
  put_u32(out, stats.attachment_count);
  put_u32(out, stats.metadata_count);
  put_u32(out, stats.chunk_count);
  put_u64(out, stats.message_start_time);
  put_u64(out, stats.message_end_time);
  put_map(out, stats.channel_message_counts);
  end_record(out, at);
}

void put_metadata_record(ByteBuffer& out, const Metadata& metadata) {
  std::size_t at = begin_record(out, Opcode::metadata);
  put_string(out, metadata.name);
  put_map(out, metadata.metadata);
  end_record(out, at);
}

void put_metadata_index_record(ByteBuffer& out, const MetadataIndex& index) {
  std::size_t at = begin_record(out, Opcode::metadata_index);
  put_u64(out, index.offset);
  put_u64(out, index.length);
  put_string(out, index.name);
  end_record(out, at);
}

// ---------------------------------------------------------------------------------------------

void Cursor::fail(StatusCode code, const std::string& what) {
  if (!status_.ok()) return;
  status_ = Status(code, where_ + ": " + what);
  pos_ = bytes_.size();
}

bool Cursor::need(std::size_t n, const char* field) {
  if (!status_.ok()) return false;
  if (remaining() >= n) return true;
  fail(StatusCode::malformed, std::string(field) + " at offset " + std::to_string(offset()) +
                                  " needs " + std::to_string(n) + " bytes, only " +
                                  std::to_string(remaining()) + " remain in the record");
  return false;
}

std::uint8_t Cursor::u8() {
  if (!need(1, "u8 field")) return 0;
  return static_cast<std::uint8_t>(bytes_[pos_++]);
}
std::uint16_t Cursor::u16() {
  if (!need(2, "u16 field")) return 0;
  auto v = load_u16(bytes_.data() + pos_);
  pos_ += 2;
  return v;
}
std::uint32_t Cursor::u32() {
  if (!need(4, "u32 field")) return 0;
  auto v = load_u32(bytes_.data() + pos_);
  pos_ += 4;
  return v;
}
std::uint64_t Cursor::u64() {
  if (!need(8, "u64 field")) return 0;
  auto v = load_u64(bytes_.data() + pos_);
  pos_ += 8;
  return v;
}

std::span<const std::byte> Cursor::bytes32(const char* field) {
  if (!need(4, field)) return {};
  std::uint32_t n = load_u32(bytes_.data() + pos_);
  pos_ += 4;
  if (!need(n, field)) return {};
  auto view = bytes_.subspan(pos_, n);
  pos_ += n;
  return view;
}

std::span<const std::byte> Cursor::bytes64(const char* field) {
  if (!need(8, field)) return {};
  std::uint64_t n = load_u64(bytes_.data() + pos_);
  pos_ += 8;
  if (n > remaining()) {
    fail(StatusCode::malformed, std::string(field) + " at offset " + std::to_string(offset() - 8) +
                                    " declares " + std::to_string(n) + " bytes, only " +
                                    std::to_string(remaining()) + " remain in the record");
    return {};
  }
  auto view = bytes_.subspan(pos_, static_cast<std::size_t>(n));
  pos_ += static_cast<std::size_t>(n);
  return view;
}

std::string Cursor::string(const char* field) {
  auto view = bytes32(field);
  return std::string(reinterpret_cast<const char*>(view.data()), view.size());
}

KeyValueMap Cursor::string_map(const char* field) {
  std::uint64_t start = offset();
  auto view = bytes32(field);
  KeyValueMap map;
  if (!ok()) return map;
  Cursor inner(view, start + 4, where_);
  while (inner.ok() && inner.remaining() > 0) {
    std::string key = inner.string("map key");
    std::string value = inner.string("map value");
    if (inner.ok()) map[std::move(key)] = std::move(value);
  }
  if (!inner.ok()) status_ = inner.status();
  return map;
}

std::map<std::uint16_t, std::uint64_t> Cursor::u16_u64_map(const char* field) {
  std::uint64_t start = offset();
  auto view = bytes32(field);
  std::map<std::uint16_t, std::uint64_t> map;
  if (!ok()) return map;
  if (view.size() % 10 != 0) {
    fail(StatusCode::malformed, std::string(field) + " at offset " + std::to_string(start) +
                                    ": byte length " + std::to_string(view.size()) +
                                    " is not a multiple of 10");
    return map;
  }
  for (std::size_t i = 0; i < view.size(); i += 10) {
    map[load_u16(view.data() + i)] = load_u64(view.data() + i + 2);
  }
  return map;
}

std::span<const std::byte> Cursor::rest() {
  auto view = bytes_.subspan(pos_);
  pos_ = bytes_.size();
  return view;
}

std::string hex(std::uint64_t v) {
  char text[24];
  std::snprintf(text, sizeof(text), "0x%llx", static_cast<unsigned long long>(v));
  return text;
}

}  // namespace avs::mcap::detail
