// MCAP writer: chunked, indexed files in the layout documented in docs/bag.md.
//
// Lifecycle: open() -> add_schema()/add_channel() -> write() ... -> close(). The destructor
// closes an open file (its status is lost: call close() to see it). One thread drives the
// writer; with `background_compression` a second, internal thread compresses and writes the
// finished chunks while the caller fills the next one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string_view>

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"

namespace avs::mcap {

struct WriterOptions {
  std::string profile = "ros2";      ///< Header.profile
  std::string library = "avs-mcap";  ///< Header.library
  Compression compression = Compression::zstd;
  /// zstd: ZSTD compression level (1 = fastest); lz4: LZ4F compressionLevel (0 = fast mode).
  int compression_level = 1;
  /// A chunk is closed once its uncompressed records reach this size.
  std::uint64_t chunk_size_bytes = 4u << 20;
  bool chunk_crc = true;         ///< Chunk.uncompressed_crc (else 0 = not computed)
  bool data_section_crc = true;  ///< DataEnd.data_section_crc
  bool summary_crc = true;       ///< Footer.summary_crc
  /// Compress and write chunks on an internal thread, with at most `max_chunks_in_flight`
  /// chunks queued (write() blocks when the queue is full: back-pressure, never loss).
  bool background_compression = true;
  std::size_t max_chunks_in_flight = 2;
};

struct WriterStatistics {
  std::uint64_t message_count = 0;
  std::uint64_t message_bytes = 0;  ///< payload bytes handed to write()
  std::uint64_t chunk_count = 0;    ///< chunks written to the file so far
  std::uint64_t file_bytes = 0;     ///< bytes written to the file so far
  /// Messages of the chunks written to the file so far: after a failed write (disk full)
  /// the ones in the file; the others (the chunk being filled, queued chunks) are lost.
  std::uint64_t messages_in_file = 0;
};

class Writer {
 public:
  Writer();
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  Writer(Writer&&) noexcept;
  Writer& operator=(Writer&&) noexcept;

  /// Creates (truncates) `path` and writes the magic and Header.
  Status open(const std::filesystem::path& path, const WriterOptions& options = {});
  bool is_open() const;

  /// Registers a schema (e.g. name "sensor_msgs/msg/Image", encoding "ros2msg", data = the
  /// .msg text with dependencies appended). Identical schemas get the same id.
  Status add_schema(std::string_view name, std::string_view encoding, std::string_view data,
                    SchemaId& id_out);
  /// Registers a channel (ros2 profile: message_encoding "cdr", metadata with
  /// "offered_qos_profiles"). `schema_id` must come from add_schema() (or be 0).
  Status add_channel(std::string_view topic, std::string_view message_encoding, SchemaId schema_id,
                     const KeyValueMap& metadata, ChannelId& id_out);
  /// Appends one message (one copy of `data` into the chunk buffer).
  Status write(ChannelId channel_id, Timestamp log_time, Timestamp publish_time,
               std::span<const std::byte> data, std::uint32_t sequence = 0);
  /// A Metadata record (outside chunks) plus its Metadata Index in the summary.
  Status add_metadata(std::string_view name, const KeyValueMap& metadata);
  /// Closes the current chunk now (e.g. to bound what a crash can lose).
  Status flush_chunk();
  /// Writes the last chunk, Data End, summary, summary offsets and footer; closes the file.
  Status close();

  WriterStatistics statistics() const;
  /// WriterStatistics::messages_in_file of one channel.
  std::uint64_t messages_in_file(ChannelId channel) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace avs::mcap
