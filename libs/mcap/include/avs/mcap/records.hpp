// MCAP record types as this library exposes them (MCAP format specification, major version 0,
// https://mcap.dev/spec). Integers are the widths the specification gives; times are
// nanoseconds in the recorder's epoch (avs: Unix time).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace avs::mcap {

using SchemaId = std::uint16_t;  ///< 0 means "no schema"
using ChannelId = std::uint16_t;
using Timestamp = std::uint64_t;  ///< nanoseconds
using KeyValueMap = std::map<std::string, std::string>;

enum class Compression { none, lz4, zstd };

/// The string the Chunk record's `compression` field carries: "", "lz4", "zstd".
std::string_view compression_field(Compression compression);
/// "none", "lz4", "zstd" (for command lines); nullopt when unknown.
std::optional<Compression> parse_compression(std::string_view name);

/// Record opcodes (spec § Records).
enum class Opcode : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

inline constexpr std::size_t kMagicSize = 8;
/// 0x89 'M' 'C' 'A' 'P' '0' '\r' '\n'
inline constexpr unsigned char kMagic[kMagicSize] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
/// opcode (1) + content length (8)
inline constexpr std::size_t kRecordPrefixSize = 9;

struct Header {
  std::string profile;
  std::string library;
};

struct Schema {
  SchemaId id = 0;
  std::string name;      ///< e.g. "sensor_msgs/msg/Image"
  std::string encoding;  ///< e.g. "ros2msg"
  std::string data;      ///< schema text (bytes)
};

struct Channel {
  ChannelId id = 0;
  SchemaId schema_id = 0;
  std::string topic;             ///< e.g. "/camera/image"
  std::string message_encoding;  ///< e.g. "cdr"
  KeyValueMap metadata;          ///< ros2: "offered_qos_profiles", "topic_type_hash"
};

/// One message as handed to a reader callback. `data` and the pointers are valid only during
/// the callback.
struct MessageView {
  const Channel* channel = nullptr;
  const Schema* schema = nullptr;  ///< nullptr when the channel has schema id 0
  std::uint32_t sequence = 0;
  Timestamp log_time = 0;
  Timestamp publish_time = 0;
  std::span<const std::byte> data;
};

struct ChunkIndex {
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  ///< whole record, opcode and length prefix included
  std::map<ChannelId, std::uint64_t> message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::map<ChannelId, std::uint64_t> channel_message_counts;
};

struct Metadata {
  std::string name;  ///< e.g. "rosbag2"
  KeyValueMap metadata;
};

struct MetadataIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;  ///< whole record
  std::string name;
};

struct Footer {
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

/// What the summary section says (or what a linear scan reconstructed).
struct Summary {
  std::map<SchemaId, Schema> schemas;
  std::map<ChannelId, Channel> channels;
  std::vector<ChunkIndex> chunk_indexes;
  std::optional<Statistics> statistics;
  std::vector<MetadataIndex> metadata_indexes;
};

}  // namespace avs::mcap
