#include <cstdio>
#include <string>

#include "avs/mcap/reader.hpp"
#include "decoder.hpp"
#include "serialize.hpp"
#include "tail_writer.hpp"

namespace avs::mcap {

namespace {

void count_message(Statistics& stats, ChannelId channel, Timestamp log_time) {
  if (stats.message_count == 0) {
    stats.message_start_time = stats.message_end_time = log_time;
  } else {
    stats.message_start_time = std::min(stats.message_start_time, log_time);
    stats.message_end_time = std::max(stats.message_end_time, log_time);
  }
  ++stats.message_count;
  ++stats.channel_message_counts[channel];
}

/// Reads the repaired file back as a strict reader would: its summary, every CRC, and the
/// message count repair says it kept.
Status verify_repaired(const std::filesystem::path& path, std::uint64_t messages_kept) {
  Reader reader;
  Status s = reader.open(path);
  if (s.ok()) s = reader.read_summary();
  ScanResult scanned;
  if (s.ok()) s = reader.scan(scanned);
  if (s.ok() && scanned.summary.statistics &&
      scanned.summary.statistics->message_count != messages_kept) {
    s = Status(StatusCode::malformed,
               "holds " + std::to_string(scanned.summary.statistics->message_count) +
                   " messages, " + std::to_string(messages_kept) + " were written");
  }
  if (s.ok()) return s;
  return Status(s.code(), "the repaired file " + path.string() + " does not read back: " +
                              s.message() + " (a bug in repair; the input is untouched)");
}

}  // namespace

Status repair_file(const std::filesystem::path& input, const std::filesystem::path& output,
                   RepairReport& report) {
  report = RepairReport{};
  std::unique_ptr<detail::Source> source;
  if (Status s = detail::open_file_source(input, source); !s.ok()) return s;
  detail::Decoder decoder(std::move(source), ReaderOptions{});
  if (Status s = decoder.open(); !s.ok()) {
    return Status(s.code(),
                  input.string() + ": cannot repair, the start of the file is bad: " + s.message());
  }
  {
    Footer footer;
    Summary summary;
    bool has_summary = false;
    report.input_had_summary =
        decoder.read_summary(footer, summary, has_summary).ok() && has_summary;
    if (report.input_had_summary && summary.statistics) {
      report.input_summary_messages = summary.statistics->message_count;
    }
  }
  std::unique_ptr<detail::Source> again;
  if (Status s = detail::open_file_source(input, again); !s.ok()) return s;
  ReaderOptions scan_options;
  scan_options.skip_corrupt_chunks = true;  // keep every intact chunk around a bad one
  detail::Decoder scanner(std::move(again), scan_options);
  if (Status s = scanner.open(); !s.ok()) return s;

  const std::filesystem::path temporary = output.string() + ".repair-tmp";
  detail::OutputFile file;
  if (Status s = file.open(temporary); !s.ok()) return s;
  detail::ByteBuffer buffer;
  buffer.append(kMagic, kMagicSize);
  std::size_t at = detail::begin_record(buffer, Opcode::header);
  detail::put_string(buffer, scanner.header().profile);
  detail::put_string(buffer, scanner.header().library);
  detail::end_record(buffer, at);
  if (Status s = file.write(buffer); !s.ok()) return s;

  detail::ByteBuffer chunk_index_records;  // the summary's Chunk Index records, as written
  std::uint32_t chunk_count = 0;
  std::vector<MetadataIndex> metadata_indexes;
  Statistics stats;
  auto copy_record = [&](const detail::RecordView& record) {
    buffer.clear();
    detail::put_u8(buffer, record.opcode);
    detail::put_u64(buffer, record.content.size());
    if (Status s = file.write(buffer); !s.ok()) return s;
    return file.write(record.content);
  };
  auto hook = [&](const detail::RecordView& record,
                  const detail::ChunkMessageIndex* chunk) -> Status {
    const auto op = static_cast<Opcode>(record.opcode);
    if (op == Opcode::message_index) return {};  // regenerated below
    const std::uint64_t offset = file.position();
    if (Status s = copy_record(record); !s.ok()) return s;
    if (op == Opcode::chunk && chunk != nullptr) {
      ChunkIndex index;
      detail::Cursor c(record.content, 0, "chunk");
      index.message_start_time = c.u64();
      index.message_end_time = c.u64();
      index.uncompressed_size = c.u64();
      (void)c.u32();
      index.compression = c.string("compression");
      index.compressed_size = c.u64();
      index.chunk_start_offset = offset;
      index.chunk_length = record.total_length();
      buffer.clear();
      detail::put_message_index_records(buffer, file.position(), *chunk,
                                        index.message_index_offsets);
      index.message_index_length = buffer.size();
      if (Status s = file.write(buffer); !s.ok()) return s;
      for (const auto& [channel, entries] : *chunk) {
        for (const auto& entry : entries) count_message(stats, channel, entry.first);
        report.messages_kept += entries.size();
      }
      detail::put_chunk_index_record(chunk_index_records, index);
      ++chunk_count;
      ++report.chunks_kept;
    } else if (op == Opcode::message) {
      detail::MessageFields fields;
      if (Status s = detail::parse_message(record.content, 0, "message", fields); s.ok()) {
        count_message(stats, fields.channel_id, fields.log_time);
        ++report.messages_kept;
      }
    } else if (op == Opcode::metadata) {
      detail::Cursor c(record.content, 0, "metadata");
      metadata_indexes.push_back({offset, record.total_length(), c.string("name")});
      ++stats.metadata_count;
    } else if (op == Opcode::attachment) {
      ++stats.attachment_count;
    }
    return {};
  };

  ScanResult scanned;
  Status scan_status = scanner.scan(scanned, /*allow_truncated=*/true, {}, hook);
  report.skipped_chunks = scanned.skipped_chunks;
  report.chunk_lengths_corrected = scanned.chunk_lengths_corrected;
  if (!scan_status.ok() && scan_status.code() == StatusCode::io_error) {
    (void)file.close();
    std::remove(temporary.c_str());
    return scan_status;
  }
  if (!scan_status.ok()) {
    report.stopped_because = scan_status.message();
    report.input_truncated = true;
  } else if (scanned.truncated) {
    report.stopped_because = scanned.truncation_detail;
    report.input_truncated = true;
    report.input_truncated_at = scanned.truncated_at;
  }
  if (scanned.data_end_offset == 0 && scanner.source().size() > scanned.last_complete_offset) {
    report.bytes_dropped = scanner.source().size() - scanned.last_complete_offset;
  }

  for (const auto& [id, channel] : scanner.channels())
    stats.channel_message_counts.try_emplace(id, 0);
  stats.schema_count = static_cast<std::uint16_t>(scanner.schemas().size());
  stats.channel_count = static_cast<std::uint32_t>(scanner.channels().size());
  stats.chunk_count = chunk_count;
  detail::TailContent tail{&scanner.schemas(), &scanner.channels(), &chunk_index_records,
                           &metadata_indexes, stats};
  Status written = detail::write_tail(file, tail, true, true);
  Status closed = file.close();
  if (!written.ok() || !closed.ok()) {
    std::remove(temporary.c_str());
    return written.ok() ? closed : written;
  }
  if (Status s = verify_repaired(temporary, report.messages_kept); !s.ok()) {
    std::remove(temporary.c_str());
    return s;
  }
  // In place, the input is the only copy of what could not be kept: it is replaced only by a
  // complete result (issue 20: one flipped bit turned an 87 KB bag into 168 bytes, exit 0).
  std::error_code same_error;
  const bool in_place = std::filesystem::equivalent(input, output, same_error);
  std::string lost;
  if (!report.skipped_chunks.empty()) {
    lost = std::to_string(report.skipped_chunks.size()) +
           " corrupt chunk(s) left out, the first at offset " +
           std::to_string(report.skipped_chunks.front().offset) + ": " +
           report.skipped_chunks.front().problem;
  } else if (!scan_status.ok()) {
    lost = "the scan stopped at a corrupt record, the rest of the file is not kept: " +
           scan_status.message();
  } else if (report.input_had_summary && report.messages_kept != report.input_summary_messages) {
    lost = "kept " + std::to_string(report.messages_kept) +
           " messages, the input's summary counts " + std::to_string(report.input_summary_messages);
  }
  std::filesystem::path destination = output;
  if (in_place && !lost.empty()) destination = output.string() + ".repaired.mcap";
  std::error_code error;
  std::filesystem::rename(temporary, destination, error);
  if (error) {
    std::remove(temporary.c_str());
    return Status(StatusCode::io_error, "rename " + temporary.string() + " -> " +
                                            destination.string() + ": " + error.message());
  }
  report.written_to = destination;
  if (in_place && !lost.empty()) {
    return Status(StatusCode::incomplete, "did not replace " + input.string() + " (" + lost +
                                              "); what could be kept is in " +
                                              destination.string() +
                                              ": check it, then move it over the input");
  }
  return {};
}

}  // namespace avs::mcap
