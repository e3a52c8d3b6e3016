#include "tail_writer.hpp"

#include "serialize.hpp"

namespace avs::mcap::detail {

void put_message_index_records(ByteBuffer& out, std::uint64_t out_file_offset,
                               const ChunkMessageIndex& index,
                               std::map<ChannelId, std::uint64_t>& offsets) {
  const std::size_t base = out.size();
  for (const auto& [channel_id, entries] : index) {
    if (entries.empty()) continue;
    offsets[channel_id] = out_file_offset + (out.size() - base);
    std::size_t at = begin_record(out, Opcode::message_index);
    put_u16(out, channel_id);
    put_u32(out, static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [log_time, offset] : entries) {
      put_u64(out, log_time);
      put_u64(out, offset);
    }
    end_record(out, at);
  }
}

void put_chunk_header(ByteBuffer& out, Timestamp start, Timestamp end,
                      std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc,
                      std::string_view compression, std::uint64_t compressed_size) {
  put_u8(out, static_cast<std::uint8_t>(Opcode::chunk));
  put_u64(out, 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + compressed_size);
  put_u64(out, start);
  put_u64(out, end);
  put_u64(out, uncompressed_size);
  put_u32(out, uncompressed_crc);
  put_string(out, compression);
  put_u64(out, compressed_size);
}

Status write_tail(OutputFile& file, const TailContent& content, bool data_section_crc,
                  bool summary_crc) {
  ByteBuffer buffer;
  // Data End: the CRC covers every byte before this record.
  std::size_t at = begin_record(buffer, Opcode::data_end);
  put_u32(buffer, data_section_crc ? file.crc() : 0);
  end_record(buffer, at);
  if (Status s = file.write(buffer); !s.ok()) return s;
  buffer.clear();

  file.set_crc_enabled(true);
  file.reset_crc();
  const std::uint64_t summary_start = file.position();
  struct Group {
    Opcode op;
    std::uint64_t start;
    std::uint64_t length;
  };
  std::vector<Group> groups;
  auto add_group = [&](Opcode op, auto&& put_all) {
    std::size_t before = buffer.size();
    put_all();
    if (buffer.size() > before) {
      groups.push_back({op, summary_start + before, buffer.size() - before});
    }
  };
  add_group(Opcode::schema, [&] {
    for (const auto& [id, schema] : *content.schemas) put_schema_record(buffer, schema);
  });
  add_group(Opcode::channel, [&] {
    for (const auto& [id, channel] : *content.channels) put_channel_record(buffer, channel);
  });
  add_group(Opcode::chunk_index, [&] { buffer.append(content.chunk_index_records->span()); });
  add_group(Opcode::statistics, [&] { put_statistics_record(buffer, content.statistics); });
  add_group(Opcode::metadata_index, [&] {
    for (const MetadataIndex& index : *content.metadata_indexes) {
      put_metadata_index_record(buffer, index);
    }
  });
  const std::uint64_t summary_offset_start = summary_start + buffer.size();
  for (const Group& group : groups) {
    std::size_t record = begin_record(buffer, Opcode::summary_offset);
    put_u8(buffer, static_cast<std::uint8_t>(group.op));
    put_u64(buffer, group.start);
    put_u64(buffer, group.length);
    end_record(buffer, record);
  }
  // Footer: the summary CRC runs from summary_start through summary_offset_start.
  put_u8(buffer, static_cast<std::uint8_t>(Opcode::footer));
  put_u64(buffer, 8 + 8 + 4);
  put_u64(buffer, summary_start);
  put_u64(buffer, summary_offset_start);
  if (Status s = file.write(buffer); !s.ok()) return s;
  buffer.clear();
  put_u32(buffer, summary_crc ? file.crc() : 0);
  buffer.append(kMagic, kMagicSize);
  return file.write(buffer);
}

}  // namespace avs::mcap::detail
