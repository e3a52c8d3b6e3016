// The reading machinery shared by Reader, repair_file() and read_bag_info(): record framing,
// chunk loading (decompression + CRC), the linear scan, the summary, and the log-time merge.
// Every offset and length from the file is checked before use. Internal to avs::mcap.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "avs/mcap/reader.hpp"
#include "byte_buffer.hpp"
#include "file_io.hpp"
#include "tail_writer.hpp"

namespace avs::mcap::detail {

struct RecordView {
  std::uint64_t offset = 0;  ///< of the opcode byte
  std::uint8_t opcode = 0;
  std::span<const std::byte> content;
  std::uint64_t total_length() const { return kRecordPrefixSize + content.size(); }
};

struct ChunkView {
  std::uint64_t offset = 0;  ///< of the Chunk record
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::span<const std::byte> records;  ///< uncompressed
};

struct MessageFields {
  ChannelId channel_id = 0;
  std::uint32_t sequence = 0;
  Timestamp log_time = 0;
  Timestamp publish_time = 0;
  std::span<const std::byte> data;
};

/// Called for every complete top-level data-section record during a scan (before Data End);
/// for chunks, `chunk_index` holds the message index rebuilt from the chunk's content.
using RecordHook =
    std::function<Status(const RecordView& record, const ChunkMessageIndex* chunk_index)>;

const char* opcode_name(std::uint8_t opcode);

class Decoder {
 public:
  Decoder(std::unique_ptr<Source> source, const ReaderOptions& options);

  Status open();  ///< leading magic + Header
  Source& source() { return *source_; }
  const Header& header() const { return header_; }
  std::uint64_t header_end() const { return header_end_; }

  Status read_summary(Footer& footer, Summary& summary, bool& has_summary);
  Status scan(ScanResult& result, bool allow_truncated, const MessageCallback& on_message,
              const RecordHook& hook);
  /// `trust_index_channels`: skip chunks whose message_index_offsets lack wanted channels.
  Status read_indexed(const Summary& summary, std::uint64_t data_limit, bool trust_index_channels,
                      const ReadOptions& options, const MessageCallback& on_message,
                      std::uint64_t& delivered, std::vector<SkippedChunk>& skipped);

  /// The Metadata record a Metadata Index points at.
  Status read_metadata(const MetadataIndex& index, Metadata& out);

  const std::map<SchemaId, Schema>& schemas() const { return schemas_; }
  const std::map<ChannelId, Channel>& channels() const { return channels_; }

 private:
  Status read_record(std::uint64_t offset, std::uint64_t limit, ByteBuffer& scratch,
                     RecordView& out);
  /// The record at `offset` taken as `length` content bytes, whatever its length field says.
  Status view_record(std::uint64_t offset, std::uint64_t length, ByteBuffer& scratch,
                     RecordView& out);
  // Resynchronisation (ReaderOptions::skip_corrupt_chunks): a record's length field is one u64
  // among its bytes, and a flipped bit in it must not cost every record after it.
  /// The content length a Chunk at `offset` has by its own fields (40 bytes of fixed fields, the
  /// compression name, the records), when they fit before `limit`; 0 when they do not.
  std::uint64_t chunk_framed_by_its_fields(std::uint64_t offset, std::uint64_t limit);
  /// Whether a data-section record can start at `offset`: an opcode allowed there and a length
  /// that fits before `limit`, or `offset == limit` (a file that ends after a record).
  bool plausible_record(std::uint64_t offset, std::uint64_t limit);
  /// The first offset from `from` at which an intact Chunk starts (it loads, its CRC checked)
  /// or a Data End followed by a summary record or the Footer; `limit` when there is none.
  std::uint64_t next_intact_record(std::uint64_t from, std::uint64_t limit);
  Status load_chunk(const RecordView& record, ByteBuffer& decompressed, ChunkView& out);
  Status add_schema(Schema schema, std::uint64_t offset);
  Status add_channel(Channel channel, std::uint64_t offset);
  /// Parses Schema/Channel records into the tables and Message records into `on_message`
  /// (with the uncompressed offset of the record).
  Status walk_chunk(const ChunkView& chunk,
                    const std::function<Status(std::uint64_t, const MessageFields&)>& on_message);
  MessageView make_view(const MessageFields& fields) const;

  std::unique_ptr<Source> source_;
  ReaderOptions options_;
  Header header_;
  std::uint64_t header_end_ = 0;
  std::map<SchemaId, Schema> schemas_;
  std::map<ChannelId, Channel> channels_;
};

Status parse_schema(std::span<const std::byte> content, std::uint64_t base,
                    const std::string& where, Schema& out);
Status parse_channel(std::span<const std::byte> content, std::uint64_t base,
                     const std::string& where, Channel& out);
Status parse_message(std::span<const std::byte> content, std::uint64_t base,
                     const std::string& where, MessageFields& out);

}  // namespace avs::mcap::detail
