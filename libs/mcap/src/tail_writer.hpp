// The end of a file, shared by Writer::close() and repair_file(): Message Index records,
// Data End, the summary section (grouped by opcode), Summary Offsets, Footer and magic.
#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"
#include "byte_buffer.hpp"
#include "file_io.hpp"

namespace avs::mcap::detail {

/// (log_time, offset of the Message record in the uncompressed chunk records) per channel.
using ChunkMessageIndex = std::map<ChannelId, std::vector<std::pair<Timestamp, std::uint64_t>>>;

/// Appends one Message Index record per channel with entries; `out_file_offset` is where
/// `out`'s first byte will land in the file. Fills `offsets` (channel -> record offset).
void put_message_index_records(ByteBuffer& out, std::uint64_t out_file_offset,
                               const ChunkMessageIndex& index,
                               std::map<ChannelId, std::uint64_t>& offsets);

/// Appends a Chunk record header (everything before the `records` bytes).
void put_chunk_header(ByteBuffer& out, Timestamp start, Timestamp end,
                      std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc,
                      std::string_view compression, std::uint64_t compressed_size);

struct TailContent {
  const std::map<SchemaId, Schema>* schemas = nullptr;
  const std::map<ChannelId, Channel>* channels = nullptr;
  /// The Chunk Index records, serialized as each chunk was written (a recording keeps one per
  /// chunk until the end: as bytes they take a third of the memory of ChunkIndex structs).
  const ByteBuffer* chunk_index_records = nullptr;
  const std::vector<MetadataIndex>* metadata_indexes = nullptr;
  Statistics statistics;
};

/// Writes Data End (CRC = file.crc() when `data_section_crc`), the summary, Summary Offsets,
/// Footer and the trailing magic.
Status write_tail(OutputFile& file, const TailContent& content, bool data_section_crc,
                  bool summary_crc);

}  // namespace avs::mcap::detail
