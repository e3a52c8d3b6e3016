#include "decoder.hpp"

#include <algorithm>
#include <cstring>
#include <queue>
#include <set>

#include "checksum.hpp"
#include "compression.hpp"
#include "serialize.hpp"

namespace avs::mcap::detail {

namespace {

constexpr std::uint64_t kFooterRecordSize = kRecordPrefixSize + 8 + 8 + 4;

std::string at(std::uint64_t offset) {
  return "offset " + std::to_string(offset);
}

std::string record_where(const RecordView& r) {
  return std::string(opcode_name(r.opcode)) + " record at " + at(r.offset);
}

}  // namespace

const char* opcode_name(std::uint8_t opcode) {
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::header:
      return "Header";
    case Opcode::footer:
      return "Footer";
    case Opcode::schema:
      return "Schema";
    case Opcode::channel:
      return "Channel";
    case Opcode::message:
      return "Message";
    case Opcode::chunk:
      return "Chunk";
    case Opcode::message_index:
      return "Message Index";
    case Opcode::chunk_index:
      return "Chunk Index";
    case Opcode::attachment:
      return "Attachment";
    case Opcode::attachment_index:
      return "Attachment Index";
    case Opcode::statistics:
      return "Statistics";
    case Opcode::metadata:
      return "Metadata";
    case Opcode::metadata_index:
      return "Metadata Index";
    case Opcode::summary_offset:
      return "Summary Offset";
    case Opcode::data_end:
      return "Data End";
  }
  return opcode == 0 ? "invalid opcode 0x00" : "unknown-opcode";
}

Status parse_schema(std::span<const std::byte> content, std::uint64_t base,
                    const std::string& where, Schema& out) {
  Cursor c(content, base, where);
  out.id = c.u16();
  out.name = c.string("schema name");
  out.encoding = c.string("schema encoding");
  auto data = c.bytes32("schema data");
  out.data.assign(reinterpret_cast<const char*>(data.data()), data.size());
  return c.status();
}

Status parse_channel(std::span<const std::byte> content, std::uint64_t base,
                     const std::string& where, Channel& out) {
  Cursor c(content, base, where);
  out.id = c.u16();
  out.schema_id = c.u16();
  out.topic = c.string("channel topic");
  out.message_encoding = c.string("channel message_encoding");
  out.metadata = c.string_map("channel metadata");
  return c.status();
}

Status parse_message(std::span<const std::byte> content, std::uint64_t base,
                     const std::string& where, MessageFields& out) {
  Cursor c(content, base, where);
  out.channel_id = c.u16();
  out.sequence = c.u32();
  out.log_time = c.u64();
  out.publish_time = c.u64();
  out.data = c.rest();
  return c.status();
}

Decoder::Decoder(std::unique_ptr<Source> source, const ReaderOptions& options)
    : source_(std::move(source)), options_(options) {}

Status Decoder::read_metadata(const MetadataIndex& index, Metadata& out) {
  ByteBuffer scratch;
  RecordView record;
  const std::uint64_t size = source_->size();
  const std::uint64_t limit = index.offset <= size && index.length <= size - index.offset
                                  ? index.offset + index.length
                                  : size;
  if (Status s = read_record(index.offset, limit, scratch, record); !s.ok()) return s;
  const std::string where = "Metadata record at " + at(index.offset);
  if (record.opcode != static_cast<std::uint8_t>(Opcode::metadata)) {
    return Status(StatusCode::malformed,
                  where + ": the index points at a " + opcode_name(record.opcode) + " record");
  }
  Cursor c(record.content, index.offset + kRecordPrefixSize, where);
  out.name = c.string("metadata name");
  out.metadata = c.string_map("metadata");
  return c.status();
}

Status Decoder::read_record(std::uint64_t offset, std::uint64_t limit, ByteBuffer& scratch,
                            RecordView& out) {
  if (offset > limit || limit - offset < kRecordPrefixSize) {
    return Status(StatusCode::truncated, "record at " + at(offset) + ": needs " +
                                             std::to_string(kRecordPrefixSize) +
                                             " bytes for opcode and length, only " +
                                             std::to_string(offset > limit ? 0 : limit - offset) +
                                             " remain before " + at(limit));
  }
  std::span<const std::byte> prefix;
  if (Status s = source_->view(offset, kRecordPrefixSize, scratch, prefix); !s.ok()) return s;
  out.offset = offset;
  out.opcode = static_cast<std::uint8_t>(prefix[0]);
  const std::uint64_t length = load_u64(prefix.data() + 1);
  const std::uint64_t available = limit - offset - kRecordPrefixSize;
  if (length > available) {
    return Status(StatusCode::truncated, std::string(opcode_name(out.opcode)) + " record at " +
                                             at(offset) + " declares " + std::to_string(length) +
                                             " content bytes, only " + std::to_string(available) +
                                             " remain before " + at(limit));
  }
  if (length > options_.max_record_bytes) {
    return Status(StatusCode::too_large, std::string(opcode_name(out.opcode)) + " record at " +
                                             at(offset) + " has " + std::to_string(length) +
                                             " content bytes, above the reader limit " +
                                             std::to_string(options_.max_record_bytes));
  }
  return source_->view(offset + kRecordPrefixSize, length, scratch, out.content);
}

Status Decoder::view_record(std::uint64_t offset, std::uint64_t length, ByteBuffer& scratch,
                            RecordView& out) {
  out.offset = offset;
  if (Status s = source_->view(offset, 1, scratch, out.content); !s.ok()) return s;
  out.opcode = static_cast<std::uint8_t>(out.content[0]);
  return source_->view(offset + kRecordPrefixSize, length, scratch, out.content);
}

namespace {

bool allowed_in_data_section(std::uint8_t opcode) {
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::schema:
    case Opcode::channel:
    case Opcode::message:
    case Opcode::chunk:
    case Opcode::message_index:
    case Opcode::attachment:
    case Opcode::metadata:
    case Opcode::data_end:
      return true;
    default:
      return opcode >= 0x80;  // private records
  }
}

bool opens_the_summary(std::uint8_t opcode) {
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::footer:
    case Opcode::schema:
    case Opcode::channel:
    case Opcode::chunk_index:
    case Opcode::attachment_index:
    case Opcode::statistics:
    case Opcode::metadata_index:
    case Opcode::summary_offset:
      return true;
    default:
      return false;
  }
}

// Chunk content: start time, end time, uncompressed size (u64 each), CRC (u32), compression
// name (u32 length + bytes), records (u64 length + bytes).
constexpr std::uint64_t kChunkUncompressedSizeAt = 16;
constexpr std::uint64_t kChunkCompressionLengthAt = 28;
constexpr std::uint64_t kChunkFixedFields = 40;

}  // namespace

std::uint64_t Decoder::chunk_framed_by_its_fields(std::uint64_t offset, std::uint64_t limit) {
  const std::uint64_t fields_at = offset + kRecordPrefixSize;
  if (fields_at > limit || limit - fields_at < kChunkFixedFields) return 0;
  ByteBuffer probe;
  std::span<const std::byte> bytes;
  if (!source_->view(fields_at + kChunkCompressionLengthAt, 4, probe, bytes).ok()) return 0;
  const std::uint64_t name_length = load_u32(bytes.data());
  const std::uint64_t room = limit - fields_at - kChunkFixedFields;
  if (name_length > room) return 0;
  if (!source_->view(fields_at + kChunkFixedFields - 8 + name_length, 8, probe, bytes).ok()) {
    return 0;
  }
  const std::uint64_t records_length = load_u64(bytes.data());
  if (records_length > room - name_length) return 0;
  return kChunkFixedFields + name_length + records_length;
}

bool Decoder::plausible_record(std::uint64_t offset, std::uint64_t limit) {
  if (offset == limit) return true;
  if (offset > limit || limit - offset < kRecordPrefixSize) return false;
  ByteBuffer probe;
  std::span<const std::byte> prefix;
  if (!source_->view(offset, kRecordPrefixSize, probe, prefix).ok()) return false;
  return allowed_in_data_section(static_cast<std::uint8_t>(prefix[0])) &&
         load_u64(prefix.data() + 1) <= limit - offset - kRecordPrefixSize;
}

std::uint64_t Decoder::next_intact_record(std::uint64_t from, std::uint64_t limit) {
  constexpr std::uint64_t kWindow = 1 << 16;
  ByteBuffer window_buffer;
  ByteBuffer raw;
  ByteBuffer decompressed;
  // Bounded work: a hostile file may hold many candidates that decompress to the chunk limit.
  std::uint64_t budget_bytes = options_.max_loaded_uncompressed_bytes;
  for (std::uint64_t start = from; start < limit && limit - start >= kRecordPrefixSize;
       start += kWindow) {
    // Each window overlaps the next by a prefix, so that no candidate straddles two unseen.
    const std::uint64_t length = std::min(limit - start, kWindow + kRecordPrefixSize - 1);
    std::span<const std::byte> window;
    if (!source_->view(start, length, window_buffer, window).ok()) return limit;
    for (std::uint64_t i = 0; i + kRecordPrefixSize <= window.size() && i < kWindow; ++i) {
      const auto opcode = static_cast<Opcode>(window[i]);
      if (opcode != Opcode::chunk && opcode != Opcode::data_end) continue;
      const std::uint64_t at_offset = start + i;
      const std::uint64_t declared = load_u64(window.data() + i + 1);
      if (declared > limit - at_offset - kRecordPrefixSize) continue;
      const std::uint64_t end = at_offset + kRecordPrefixSize + declared;
      if (opcode == Opcode::data_end) {
        if (declared != 4 || limit - end < kRecordPrefixSize) continue;
        std::span<const std::byte> next;
        if (!source_->view(end, kRecordPrefixSize, raw, next).ok()) return limit;
        if (opens_the_summary(static_cast<std::uint8_t>(next[0])) &&
            load_u64(next.data() + 1) <= limit - end - kRecordPrefixSize) {
          return at_offset;
        }
        continue;
      }
      // A Chunk: its length field and its fields agree, it decompresses, its CRC (when it has
      // one) matches and its records parse.
      // (framed is 0 when the fields do not fit: never a match, a Chunk has 40 bytes of fields.)
      const std::uint64_t framed = chunk_framed_by_its_fields(at_offset, limit);
      if (framed == 0 || framed != declared) continue;
      RecordView record;
      if (!view_record(at_offset, declared, raw, record).ok()) return limit;
      // (Above the chunk limit load_chunk refuses it before decompressing: nothing to count.)
      const std::uint64_t uncompressed = load_u64(record.content.data() + kChunkUncompressedSizeAt);
      if (uncompressed <= options_.max_chunk_uncompressed_bytes) {
        if (uncompressed > budget_bytes) return limit;
        budget_bytes -= uncompressed;
      }
      ChunkView chunk;
      if (!load_chunk(record, decompressed, chunk).ok()) continue;
      if (chunk.uncompressed_crc == 0 &&
          !walk_chunk(chunk, [](std::uint64_t, const MessageFields&) { return Status{}; }).ok()) {
        continue;
      }
      return at_offset;
    }
  }
  return limit;
}

Status Decoder::open() {
  const std::uint64_t size = source_->size();
  if (size < kMagicSize) {
    return Status(StatusCode::truncated, "file of " + std::to_string(size) +
                                             " bytes is too short for the MCAP magic at " + at(0));
  }
  ByteBuffer scratch;
  std::span<const std::byte> magic;
  if (Status s = source_->view(0, kMagicSize, scratch, magic); !s.ok()) return s;
  if (std::memcmp(magic.data(), kMagic, kMagicSize) != 0) {
    return Status(StatusCode::malformed, "not an MCAP file: bad magic at " + at(0));
  }
  RecordView header;
  if (Status s = read_record(kMagicSize, size, scratch, header); !s.ok()) return s;
  if (header.opcode != static_cast<std::uint8_t>(Opcode::header)) {
    return Status(StatusCode::malformed, "first record at " + at(kMagicSize) + " is " +
                                             opcode_name(header.opcode) + ", not Header");
  }
  Cursor c(header.content, kMagicSize + kRecordPrefixSize, "Header record at " + at(kMagicSize));
  header_.profile = c.string("profile");
  header_.library = c.string("library");
  header_end_ = kMagicSize + header.total_length();
  return c.status();
}

Status Decoder::add_schema(Schema schema, std::uint64_t offset) {
  if (schema.id == 0) return {};  // spec: ignored by readers
  auto [it, inserted] = schemas_.emplace(schema.id, schema);
  if (!inserted && (it->second.name != schema.name || it->second.encoding != schema.encoding ||
                    it->second.data != schema.data)) {
    return Status(StatusCode::malformed, "Schema record at " + at(offset) +
                                             " redefines schema id " + std::to_string(schema.id) +
                                             " differently");
  }
  return {};
}

Status Decoder::add_channel(Channel channel, std::uint64_t offset) {
  auto [it, inserted] = channels_.emplace(channel.id, channel);
  if (!inserted &&
      (it->second.topic != channel.topic ||
       it->second.message_encoding != channel.message_encoding ||
       it->second.schema_id != channel.schema_id || it->second.metadata != channel.metadata)) {
    return Status(StatusCode::malformed, "Channel record at " + at(offset) +
                                             " redefines channel id " + std::to_string(channel.id) +
                                             " differently");
  }
  return {};
}

Status Decoder::load_chunk(const RecordView& record, ByteBuffer& decompressed, ChunkView& out) {
  const std::string where = "Chunk record at " + at(record.offset);
  Cursor c(record.content, record.offset + kRecordPrefixSize, where);
  out.offset = record.offset;
  out.message_start_time = c.u64();
  out.message_end_time = c.u64();
  out.uncompressed_size = c.u64();
  out.uncompressed_crc = c.u32();
  out.compression = c.string("compression");
  auto stored = c.bytes64("records");
  if (!c.ok()) return c.status();
  out.compressed_size = stored.size();
  if (out.uncompressed_size > options_.max_chunk_uncompressed_bytes) {
    return Status(StatusCode::too_large, where + ": uncompressed_size " +
                                             std::to_string(out.uncompressed_size) +
                                             " is above the reader limit " +
                                             std::to_string(options_.max_chunk_uncompressed_bytes));
  }
  if (out.compression.empty()) {
    if (stored.size() != out.uncompressed_size) {
      return Status(StatusCode::malformed,
                    where + ": uncompressed chunk holds " + std::to_string(stored.size()) +
                        " bytes, uncompressed_size says " + std::to_string(out.uncompressed_size));
    }
    out.records = stored;
  } else {
    if (Status s =
            decompress(out.compression, stored, out.uncompressed_size, record.offset, decompressed);
        !s.ok()) {
      return s;
    }
    out.records = decompressed.span();
  }
  if (options_.verify_chunk_crc && out.uncompressed_crc != 0) {
    std::uint32_t computed = crc32_update(0, out.records);
    if (computed != out.uncompressed_crc) {
      return Status(StatusCode::crc_mismatch, where + ": CRC of the uncompressed records is " +
                                                  hex(computed) + ", the chunk says " +
                                                  hex(out.uncompressed_crc));
    }
  }
  return {};
}

Status Decoder::walk_chunk(
    const ChunkView& chunk,
    const std::function<Status(std::uint64_t, const MessageFields&)>& on_message) {
  const std::string chunk_where = "Chunk record at " + at(chunk.offset);
  std::uint64_t pos = 0;
  const std::uint64_t size = chunk.records.size();
  while (pos < size) {
    const std::string where =
        chunk_where + ", inner record at uncompressed offset " + std::to_string(pos);
    if (size - pos < kRecordPrefixSize) {
      return Status(StatusCode::malformed, where + ": needs 9 bytes for opcode and length, only " +
                                               std::to_string(size - pos) + " remain");
    }
    const auto opcode = static_cast<std::uint8_t>(chunk.records[pos]);
    const std::uint64_t length = load_u64(chunk.records.data() + pos + 1);
    if (length > size - pos - kRecordPrefixSize) {
      return Status(StatusCode::malformed, where + " (" + opcode_name(opcode) + ") declares " +
                                               std::to_string(length) + " bytes, only " +
                                               std::to_string(size - pos - kRecordPrefixSize) +
                                               " remain in the chunk");
    }
    auto content = chunk.records.subspan(pos + kRecordPrefixSize, length);
    const std::uint64_t base = pos + kRecordPrefixSize;
    switch (static_cast<Opcode>(opcode)) {
      case Opcode::schema: {
        Schema schema;
        if (Status s = parse_schema(content, base, where, schema); !s.ok()) return s;
        if (Status s = add_schema(std::move(schema), chunk.offset); !s.ok()) return s;
        break;
      }
      case Opcode::channel: {
        Channel channel;
        if (Status s = parse_channel(content, base, where, channel); !s.ok()) return s;
        if (Status s = add_channel(std::move(channel), chunk.offset); !s.ok()) return s;
        break;
      }
      case Opcode::message: {
        MessageFields fields;
        if (Status s = parse_message(content, base, where, fields); !s.ok()) return s;
        if (channels_.count(fields.channel_id) == 0) {
          return Status(StatusCode::malformed, where + ": Message on unknown channel id " +
                                                   std::to_string(fields.channel_id));
        }
        if (Status s = on_message(pos, fields); !s.ok()) return s;
        break;
      }
      default:
        if (opcode == 0 || opcode < 0x80) {
          return Status(StatusCode::malformed,
                        where + ": " + opcode_name(opcode) + " is not allowed inside a chunk");
        }
        break;  // private opcodes are skipped
    }
    pos += kRecordPrefixSize + length;
  }
  return {};
}

MessageView Decoder::make_view(const MessageFields& fields) const {
  MessageView view;
  const Channel& channel = channels_.at(fields.channel_id);  // checked by the caller
  view.channel = &channel;
  auto schema = schemas_.find(channel.schema_id);
  view.schema = schema == schemas_.end() ? nullptr : &schema->second;
  view.sequence = fields.sequence;
  view.log_time = fields.log_time;
  view.publish_time = fields.publish_time;
  view.data = fields.data;
  return view;
}

// ---------------------------------------------------------------------------------------------
// Summary (fast path).

Status Decoder::read_summary(Footer& footer, Summary& summary, bool& has_summary) {
  has_summary = false;
  const std::uint64_t size = source_->size();
  if (size < header_end_ + kFooterRecordSize + kMagicSize) {
    return Status(StatusCode::truncated, "no room for a Footer: file of " + std::to_string(size) +
                                             " bytes ends right after the Header (which ends at " +
                                             at(header_end_) + ")");
  }
  ByteBuffer scratch;
  std::span<const std::byte> tail;
  const std::uint64_t footer_offset = size - kMagicSize - kFooterRecordSize;
  if (Status s = source_->view(footer_offset, kFooterRecordSize + kMagicSize, scratch, tail);
      !s.ok()) {
    return s;
  }
  if (std::memcmp(tail.data() + kFooterRecordSize, kMagic, kMagicSize) != 0) {
    return Status(StatusCode::truncated, "no trailing magic at " + at(size - kMagicSize) +
                                             " (file truncated, or the writer did not close it)");
  }
  if (static_cast<std::uint8_t>(tail[0]) != static_cast<std::uint8_t>(Opcode::footer) ||
      load_u64(tail.data() + 1) != 20) {
    return Status(StatusCode::malformed,
                  "no Footer record (opcode 0x02, length 20) at " + at(footer_offset));
  }
  footer.summary_start = load_u64(tail.data() + 9);
  footer.summary_offset_start = load_u64(tail.data() + 17);
  footer.summary_crc = load_u32(tail.data() + 25);
  if (footer.summary_start == 0) return {};  // valid file without a summary
  if (footer.summary_start < header_end_ || footer.summary_start > footer_offset) {
    return Status(StatusCode::malformed, "Footer at " + at(footer_offset) + ": summary_start " +
                                             std::to_string(footer.summary_start) +
                                             " lies outside [" + std::to_string(header_end_) +
                                             ", " + std::to_string(footer_offset) + "]");
  }
  std::uint64_t summary_end = footer_offset;
  if (footer.summary_offset_start != 0) {
    if (footer.summary_offset_start < footer.summary_start ||
        footer.summary_offset_start > footer_offset) {
      return Status(StatusCode::malformed,
                    "Footer at " + at(footer_offset) + ": summary_offset_start " +
                        std::to_string(footer.summary_offset_start) + " lies outside [" +
                        std::to_string(footer.summary_start) + ", " +
                        std::to_string(footer_offset) + "]");
    }
    summary_end = footer.summary_offset_start;
  }
  // One read covers the summary, the summary offsets and the footer up to its CRC field.
  ByteBuffer summary_bytes;
  std::span<const std::byte> region;
  const std::uint64_t crc_end = footer_offset + kRecordPrefixSize + 16;
  if (Status s = source_->view(footer.summary_start, crc_end - footer.summary_start, summary_bytes,
                               region);
      !s.ok()) {
    return s;
  }
  if (footer.summary_crc != 0) {
    std::uint32_t computed = crc32_update(0, region);
    if (computed != footer.summary_crc) {
      return Status(StatusCode::crc_mismatch,
                    "summary section from " + at(footer.summary_start) + " to " + at(crc_end) +
                        ": CRC is " + hex(computed) + ", the Footer at " + at(footer_offset) +
                        " says " + hex(footer.summary_crc));
    }
  }
  Summary parsed;
  std::uint64_t pos = footer.summary_start;
  while (pos < summary_end) {
    const std::uint64_t rel = pos - footer.summary_start;
    const std::uint64_t left = summary_end - pos;
    if (left < kRecordPrefixSize) {
      return Status(StatusCode::malformed, "summary record at " + at(pos) +
                                               ": needs 9 bytes for opcode and length, only " +
                                               std::to_string(left) + " remain");
    }
    RecordView record;
    record.offset = pos;
    record.opcode = static_cast<std::uint8_t>(region[rel]);
    const std::uint64_t length = load_u64(region.data() + rel + 1);
    if (length > left - kRecordPrefixSize) {
      return Status(StatusCode::malformed,
                    std::string(opcode_name(record.opcode)) + " record at " + at(pos) +
                        " declares " + std::to_string(length) + " bytes, only " +
                        std::to_string(left - kRecordPrefixSize) + " remain in the summary");
    }
    record.content = region.subspan(rel + kRecordPrefixSize, length);
    const std::string where = record_where(record);
    const std::uint64_t base = pos + kRecordPrefixSize;
    Cursor c(record.content, base, where);
    switch (static_cast<Opcode>(record.opcode)) {
      case Opcode::schema: {
        Schema schema;
        if (Status s = parse_schema(record.content, base, where, schema); !s.ok()) return s;
        if (Status s = add_schema(schema, pos); !s.ok()) return s;
        if (schema.id != 0) parsed.schemas[schema.id] = std::move(schema);
        break;
      }
      case Opcode::channel: {
        Channel channel;
        if (Status s = parse_channel(record.content, base, where, channel); !s.ok()) return s;
        if (Status s = add_channel(channel, pos); !s.ok()) return s;
        parsed.channels[channel.id] = std::move(channel);
        break;
      }
      case Opcode::chunk_index: {
        ChunkIndex index;
        index.message_start_time = c.u64();
        index.message_end_time = c.u64();
        index.chunk_start_offset = c.u64();
        index.chunk_length = c.u64();
        index.message_index_offsets = c.u16_u64_map("message_index_offsets");
        index.message_index_length = c.u64();
        index.compression = c.string("compression");
        index.compressed_size = c.u64();
        index.uncompressed_size = c.u64();
        if (!c.ok()) return c.status();
        parsed.chunk_indexes.push_back(std::move(index));
        break;
      }
      case Opcode::statistics: {
        Statistics stats;
        stats.message_count = c.u64();
        stats.schema_count = c.u16();
        stats.channel_count = c.u32();
        stats.attachment_count = c.u32();
        stats.metadata_count = c.u32();
        stats.chunk_count = c.u32();
        stats.message_start_time = c.u64();
        stats.message_end_time = c.u64();
        stats.channel_message_counts = c.u16_u64_map("channel_message_counts");
        if (!c.ok()) return c.status();
        parsed.statistics = std::move(stats);
        break;
      }
      case Opcode::metadata_index: {
        MetadataIndex index;
        index.offset = c.u64();
        index.length = c.u64();
        index.name = c.string("name");
        if (!c.ok()) return c.status();
        parsed.metadata_indexes.push_back(std::move(index));
        break;
      }
      case Opcode::attachment_index:
        break;  // attachments are not read by this library
      default:
        if (record.opcode == 0 || record.opcode < 0x80) {
          return Status(StatusCode::malformed, where + " is not allowed in the summary section");
        }
        break;
    }
    pos += kRecordPrefixSize + length;
  }
  summary = std::move(parsed);
  has_summary = true;
  return {};
}

// ---------------------------------------------------------------------------------------------
// Linear scan.

Status Decoder::scan(ScanResult& result, bool allow_truncated, const MessageCallback& on_message,
                     const RecordHook& hook) {
  result = ScanResult{};
  result.header = header_;
  const std::uint64_t size = source_->size();
  ByteBuffer scratch;
  ByteBuffer decompressed;
  std::span<const std::byte> head;
  if (Status s = source_->view(0, header_end_, scratch, head); !s.ok()) return s;
  std::uint32_t crc = crc32_update(0, head);
  Statistics stats;
  bool stopped_by_callback = false;
  ChunkIndex* last_chunk = nullptr;  // the chunk whose Message Index records may follow
  std::vector<std::pair<std::uint64_t, MessageFields>> chunk_messages;  // one chunk's, checked
  std::uint64_t pos = header_end_;
  result.last_complete_offset = pos;

  auto count_message = [&](const MessageFields& fields) {
    if (stats.message_count == 0) {
      stats.message_start_time = stats.message_end_time = fields.log_time;
    } else {
      stats.message_start_time = std::min(stats.message_start_time, fields.log_time);
      stats.message_end_time = std::max(stats.message_end_time, fields.log_time);
    }
    ++stats.message_count;
    ++stats.channel_message_counts[fields.channel_id];
  };
  auto deliver = [&](const MessageFields& fields) {
    if (on_message && !stopped_by_callback && !on_message(make_view(fields))) {
      stopped_by_callback = true;
    }
  };

  while (true) {
    RecordView record;
    if (pos == size) {
      Status missing(StatusCode::truncated,
                     "file ends at " + at(pos) + " without a Data End record");
      if (!allow_truncated) return missing;
      result.truncated = true;
      result.truncated_at = pos;
      result.truncation_detail = missing.message();
      break;
    }
    Status read = read_record(pos, size, scratch, record);
    if (options_.skip_corrupt_chunks && read.code() != StatusCode::io_error) {
      bool ends_well = read.ok();
      if (record.opcode == static_cast<std::uint8_t>(Opcode::chunk)) {
        // The chunk's own fields frame it too. Where they disagree with its length field, the
        // one that ends at a record is believed, the fields first: a length covering the next
        // chunk would otherwise hide it (issue 20 section 2).
        const std::uint64_t framed = chunk_framed_by_its_fields(pos, size);
        if (!read.ok() || framed != record.content.size()) {
          if (framed != 0 && plausible_record(pos + kRecordPrefixSize + framed, size)) {
            read = view_record(pos, framed, scratch, record);
            if (read.ok()) ++result.chunk_lengths_corrected;
            ends_well = read.ok();
          } else {
            ends_well = read.ok() && plausible_record(pos + record.total_length(), size);
          }
        }
      }
      if (!ends_well) {
        const std::uint64_t next = next_intact_record(pos + 1, size);
        if (next < size) {
          result.skipped_chunks.push_back(
              {pos, std::string(opcode_name(record.opcode)) + " record at " + at(pos) +
                        ": its framing is lost (" +
                        (read.ok() ? std::string("it does not end at a record") : read.message()) +
                        "); left out up to the next intact record, at " + at(next)});
          last_chunk = nullptr;
          pos = next;
          result.last_complete_offset = pos;
          continue;
        }
      }
    }
    if (Status s = read; !s.ok()) {
      if (s.code() != StatusCode::truncated || !allow_truncated) return s;
      result.truncated = true;
      result.truncated_at = pos;
      result.truncation_detail = s.message();
      break;
    }
    const std::string where = record_where(record);
    const std::uint64_t base = pos + kRecordPrefixSize;
    const auto op = static_cast<Opcode>(record.opcode);
    ChunkMessageIndex chunk_index;
    bool keep_last_chunk = false;
    bool skipped = false;  // a corrupt chunk left out (ReaderOptions::skip_corrupt_chunks)
    if (op == Opcode::data_end) {
      Cursor c(record.content, base, where);
      std::uint32_t stored = c.u32();
      if (!c.ok()) return c.status();
      // A skipped chunk's bytes are still in the CRC, and a corrected length field is not the
      // file's: it cannot match, and says nothing more.
      if (stored != 0 && result.skipped_chunks.empty() && result.chunk_lengths_corrected == 0) {
        if (stored != crc) {
          return Status(StatusCode::crc_mismatch, "data section CRC up to the Data End record at " +
                                                      at(pos) + " is " + hex(crc) +
                                                      ", the record says " + hex(stored));
        }
        result.data_crc_checked = true;
      }
      result.data_end_offset = pos;
      result.last_complete_offset = pos + record.total_length();
      break;
    }
    switch (op) {
      case Opcode::schema: {
        Schema schema;
        if (Status s = parse_schema(record.content, base, where, schema); !s.ok()) return s;
        if (Status s = add_schema(std::move(schema), pos); !s.ok()) return s;
        break;
      }
      case Opcode::channel: {
        Channel channel;
        if (Status s = parse_channel(record.content, base, where, channel); !s.ok()) return s;
        if (Status s = add_channel(std::move(channel), pos); !s.ok()) return s;
        break;
      }
      case Opcode::message: {
        MessageFields fields;
        if (Status s = parse_message(record.content, base, where, fields); !s.ok()) return s;
        if (channels_.count(fields.channel_id) == 0) {
          return Status(StatusCode::malformed,
                        where + ": unknown channel id " + std::to_string(fields.channel_id));
        }
        ++result.loose_message_count;
        count_message(fields);
        deliver(fields);
        break;
      }
      case Opcode::chunk: {
        // The whole chunk is checked before any of its messages is counted or delivered, so
        // that a chunk skipped as corrupt contributes nothing.
        ChunkView chunk;
        chunk_messages.clear();
        Status loaded = load_chunk(record, decompressed, chunk);
        if (loaded.ok()) {
          loaded = walk_chunk(chunk, [&](std::uint64_t offset, const MessageFields& fields) {
            chunk_messages.emplace_back(offset, fields);
            return Status{};
          });
        }
        if (!loaded.ok()) {
          if (!options_.skip_corrupt_chunks || loaded.code() == StatusCode::io_error) {
            return loaded;
          }
          result.skipped_chunks.push_back({pos, loaded.message()});
          skipped = true;
          break;
        }
        for (const auto& [offset, fields] : chunk_messages) {
          chunk_index[fields.channel_id].emplace_back(fields.log_time, offset);
          count_message(fields);
          deliver(fields);
        }
        ChunkIndex index;
        index.message_start_time = chunk.message_start_time;
        index.message_end_time = chunk.message_end_time;
        index.chunk_start_offset = pos;
        index.chunk_length = record.total_length();
        index.compression = chunk.compression;
        index.compressed_size = chunk.compressed_size;
        index.uncompressed_size = chunk.uncompressed_size;
        result.summary.chunk_indexes.push_back(std::move(index));
        last_chunk = &result.summary.chunk_indexes.back();
        keep_last_chunk = true;
        break;
      }
      case Opcode::message_index: {
        Cursor c(record.content, base, where);
        ChannelId channel = c.u16();
        auto entries = c.bytes32("records");
        if (!c.ok()) return c.status();
        if (entries.size() % 16 != 0) {
          return Status(StatusCode::malformed, where + ": records byte length " +
                                                   std::to_string(entries.size()) +
                                                   " is not a multiple of 16");
        }
        if (last_chunk != nullptr) {
          last_chunk->message_index_offsets[channel] = pos;
          last_chunk->message_index_length += record.total_length();
          keep_last_chunk = true;
        }
        break;
      }
      case Opcode::metadata: {
        Cursor c(record.content, base, where);
        MetadataIndex index{pos, record.total_length(), c.string("name")};
        (void)c.string_map("metadata");
        if (!c.ok()) return c.status();
        result.summary.metadata_indexes.push_back(std::move(index));
        ++stats.metadata_count;
        break;
      }
      case Opcode::attachment:
        ++stats.attachment_count;
        break;
      default:
        if (record.opcode == 0 || record.opcode < 0x80) {
          return Status(StatusCode::malformed,
                        where + " is not allowed in the data section (Data End missing?)");
        }
        break;  // private records are skipped
    }
    if (!keep_last_chunk) last_chunk = nullptr;
    if (hook && !skipped) {
      if (Status s = hook(record, op == Opcode::chunk ? &chunk_index : nullptr); !s.ok()) {
        return s;
      }
    }
    // The data CRC covers the raw record (prefix re-encoded: identical to the file bytes).
    unsigned char prefix[kRecordPrefixSize];
    prefix[0] = record.opcode;
    write_u64_at(reinterpret_cast<std::byte*>(prefix + 1), record.content.size());
    crc = crc32_update(crc, std::as_bytes(std::span(prefix)));
    crc = crc32_update(crc, record.content);
    pos += record.total_length();
    result.last_complete_offset = pos;
    if (stopped_by_callback) break;
  }
  result.summary.schemas = schemas_;
  result.summary.channels = channels_;
  stats.schema_count = static_cast<std::uint16_t>(schemas_.size());
  stats.channel_count = static_cast<std::uint32_t>(channels_.size());
  stats.chunk_count = static_cast<std::uint32_t>(result.summary.chunk_indexes.size());
  for (const auto& [id, channel] : channels_) stats.channel_message_counts.try_emplace(id, 0);
  result.summary.statistics = std::move(stats);
  return {};
}

// ---------------------------------------------------------------------------------------------
// Log-time ordered read through chunk indexes: a k-way merge over the chunks whose time range
// may hold the next message.

Status Decoder::read_indexed(const Summary& summary, std::uint64_t data_limit,
                             bool trust_index_channels, const ReadOptions& options,
                             const MessageCallback& on_message, std::uint64_t& delivered,
                             std::vector<SkippedChunk>& skipped) {
  std::set<ChannelId> wanted;
  const bool filter_topics = !options.topics.empty();
  for (const auto& [id, channel] : channels_) {
    if (!filter_topics || options.topics.count(channel.topic) > 0) wanted.insert(id);
  }
  std::vector<const ChunkIndex*> chunks;
  for (const ChunkIndex& index : summary.chunk_indexes) {
    if (index.message_end_time < options.start_time ||
        index.message_start_time > options.end_time) {
      continue;
    }
    if (filter_topics && trust_index_channels && !index.message_index_offsets.empty()) {
      bool any = std::any_of(index.message_index_offsets.begin(), index.message_index_offsets.end(),
                             [&](const auto& entry) { return wanted.count(entry.first) > 0; });
      if (!any) continue;
    }
    chunks.push_back(&index);
  }
  std::stable_sort(chunks.begin(), chunks.end(), [](const ChunkIndex* a, const ChunkIndex* b) {
    if (a->message_start_time != b->message_start_time) {
      return a->message_start_time < b->message_start_time;
    }
    return a->chunk_start_offset < b->chunk_start_offset;
  });

  struct Entry {
    Timestamp log_time;
    std::uint64_t offset;
    MessageFields fields;
  };
  struct Slot {
    ByteBuffer raw;
    ByteBuffer decompressed;
    std::vector<Entry> entries;
    std::size_t next = 0;
    std::size_t order = 0;
    std::uint64_t held_bytes = 0;  ///< counted against max_loaded_uncompressed_bytes
  };
  std::vector<std::unique_ptr<Slot>> slots;
  std::vector<std::size_t> free_slots;
  struct Head {
    Timestamp log_time;
    std::size_t order;
    std::size_t entry;
    std::size_t slot;
    bool operator>(const Head& o) const {
      if (log_time != o.log_time) return log_time > o.log_time;
      if (order != o.order) return order > o.order;
      return entry > o.entry;
    }
  };
  std::priority_queue<Head, std::vector<Head>, std::greater<Head>> heads;
  std::uint64_t loaded_bytes = 0;  // uncompressed bytes of the chunks held by the merge
  auto release = [&](std::size_t slot_id) {
    Slot& slot = *slots[slot_id];
    loaded_bytes -= slot.held_bytes;
    slot.held_bytes = 0;
    free_slots.push_back(slot_id);
  };

  auto load_one = [&](std::size_t order) -> Status {
    const ChunkIndex& index = *chunks[order];
    const std::string where = "Chunk Index for the chunk at " + at(index.chunk_start_offset);
    if (index.chunk_start_offset < header_end_ || index.chunk_start_offset > data_limit ||
        index.chunk_length > data_limit - index.chunk_start_offset ||
        index.chunk_length < kRecordPrefixSize) {
      return Status(StatusCode::malformed,
                    where + ": chunk_length " + std::to_string(index.chunk_length) +
                        " does not fit in the data section [" + std::to_string(header_end_) + ", " +
                        std::to_string(data_limit) + ")");
    }
    std::size_t slot_id;
    if (!free_slots.empty()) {
      slot_id = free_slots.back();
      free_slots.pop_back();
    } else {
      slot_id = slots.size();
      slots.push_back(std::make_unique<Slot>());
    }
    Slot& slot = *slots[slot_id];
    slot.entries.clear();
    slot.next = 0;
    slot.order = order;
    RecordView record;
    // Skipping corrupt chunks, the summary's length (under the summary CRC) is believed over a
    // chunk's own length field: a flipped bit there costs nothing.
    const bool by_index = options_.skip_corrupt_chunks && index.chunk_length >= kRecordPrefixSize;
    if (Status s =
            by_index ? view_record(index.chunk_start_offset, index.chunk_length - kRecordPrefixSize,
                                   slot.raw, record)
                     : read_record(index.chunk_start_offset,
                                   index.chunk_start_offset + index.chunk_length, slot.raw, record);
        !s.ok()) {
      free_slots.push_back(slot_id);
      return Status(StatusCode::malformed, where + ": " + s.message());
    }
    if (record.opcode != static_cast<std::uint8_t>(Opcode::chunk) ||
        record.total_length() != index.chunk_length) {
      free_slots.push_back(slot_id);
      return Status(StatusCode::malformed, where + " does not point at a Chunk record of length " +
                                               std::to_string(index.chunk_length) + " (found " +
                                               opcode_name(record.opcode) + ")");
    }
    ChunkView chunk;
    if (Status s = load_chunk(record, slot.decompressed, chunk); !s.ok()) {
      free_slots.push_back(slot_id);
      return s;
    }
    slot.held_bytes = chunk.uncompressed_size;
    loaded_bytes += slot.held_bytes;
    Status walked = walk_chunk(chunk, [&](std::uint64_t offset, const MessageFields& fields) {
      if (fields.log_time >= options.start_time && fields.log_time <= options.end_time &&
          (!filter_topics || options.topics.count(channels_.at(fields.channel_id).topic) > 0)) {
        slot.entries.push_back({fields.log_time, offset, fields});
      }
      return Status{};
    });
    if (!walked.ok()) {
      release(slot_id);
      return walked;
    }
    std::stable_sort(slot.entries.begin(), slot.entries.end(),
                     [](const Entry& a, const Entry& b) { return a.log_time < b.log_time; });
    if (slot.entries.empty()) {
      release(slot_id);
    } else {
      heads.push({slot.entries[0].log_time, order, 0, slot_id});
    }
    return {};
  };
  // A chunk that cannot be read: an error, or (skip_corrupt_chunks) left out and reported. The
  // memory limit of the merge is never skipped: the chunk may be intact.
  auto load = [&](std::size_t order) -> Status {
    const ChunkIndex& index = *chunks[order];
    if (index.uncompressed_size > options_.max_loaded_uncompressed_bytes - loaded_bytes) {
      return Status(StatusCode::too_large,
                    "the chunk at " + at(index.chunk_start_offset) + " (" +
                        std::to_string(index.uncompressed_size) + " bytes uncompressed) with the " +
                        std::to_string(loaded_bytes) +
                        " bytes of the chunks overlapping it in time is above the reader limit " +
                        std::to_string(options_.max_loaded_uncompressed_bytes));
    }
    Status s = load_one(order);
    if (s.ok() || !options_.skip_corrupt_chunks || s.code() == StatusCode::io_error) return s;
    skipped.push_back({index.chunk_start_offset, s.message()});
    return {};
  };

  std::size_t next_chunk = 0;
  while (true) {
    while (next_chunk < chunks.size() &&
           (heads.empty() || chunks[next_chunk]->message_start_time <= heads.top().log_time)) {
      if (Status s = load(next_chunk); !s.ok()) return s;
      ++next_chunk;
    }
    if (heads.empty()) break;
    Head head = heads.top();
    heads.pop();
    Slot& slot = *slots[head.slot];
    const Entry& entry = slot.entries[head.entry];
    ++delivered;
    if (!on_message(make_view(entry.fields))) return {};
    if (++slot.next < slot.entries.size()) {
      heads.push({slot.entries[slot.next].log_time, slot.order, slot.next, head.slot});
    } else {
      release(head.slot);
    }
  }
  return {};
}

}  // namespace avs::mcap::detail
