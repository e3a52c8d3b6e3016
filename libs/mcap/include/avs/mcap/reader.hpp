// MCAP reader: summary fast path, log-time ordered iteration through chunk indexes, and a
// linear scan for files without a summary (e.g. a recorder killed mid-run). Every length and
// offset read from the file is bounds-checked; failures name the byte offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"

namespace avs::mcap {

struct ReaderOptions {
  /// Refuse chunks whose uncompressed size exceeds this (a zstd bomb: a 101 KB file of 8 chunks
  /// claiming 128 MiB each took 2.4 GB under the old 1 GiB limit). avs writes chunks of
  /// --chunk-size (4 MiB) plus at most one message, far below.
  std::uint64_t max_chunk_uncompressed_bytes = 64ull << 20;
  /// Refuse to hold more than this many uncompressed bytes of chunks at once (the log-time merge
  /// keeps every chunk overlapping the next message's time loaded).
  std::uint64_t max_loaded_uncompressed_bytes = 256ull << 20;
  /// Refuse any single record larger than this.
  std::uint64_t max_record_bytes = 2ull << 30;
  bool verify_chunk_crc = true;
  /// A chunk whose record framing is intact but whose content is not (CRC mismatch, corrupt
  /// compression, a bad record inside, over the size limits) is skipped, said in the report
  /// (ScanResult / ReadReport::skipped_chunks), and reading goes on with the next record.
  /// A Chunk whose length field is corrupt is read by its own fields when they end at a record;
  /// a record whose framing is lost is skipped up to the next intact Chunk (or Data End), the
  /// region left out reported as a skipped chunk.
  /// Off: such a chunk is an error. `bag play` and `bag repair` skip; strict readers do not.
  bool skip_corrupt_chunks = false;
};

/// A chunk left out by ReaderOptions::skip_corrupt_chunks, and why.
struct SkippedChunk {
  std::uint64_t offset = 0;  ///< of the Chunk record
  std::string problem;       ///< the error reading it would have been
};

struct ReadOptions {
  Timestamp start_time = 0;            ///< inclusive, log time
  Timestamp end_time = ~Timestamp{0};  ///< inclusive, log time
  std::set<std::string> topics;        ///< empty: every topic
  /// Use a linear scan when the file has no usable summary.
  bool allow_fallback_scan = true;
  /// During a linear scan, stop quietly at a truncated tail (after SIGKILL) instead of failing;
  /// ReadReport::truncated_at tells where.
  bool allow_truncated = false;
};

struct ReadReport {
  bool used_summary = false;      ///< chunk indexes from the summary section
  bool used_linear_scan = false;  ///< summary absent/unusable: the data section was scanned
  std::string summary_problem;    ///< why the summary was not used
  bool truncated = false;
  std::uint64_t truncated_at = 0;  ///< offset of the first incomplete record
  std::string truncation_detail;
  std::uint64_t messages_delivered = 0;
  std::vector<SkippedChunk> skipped_chunks;  ///< with ReaderOptions::skip_corrupt_chunks
};

/// What a linear scan of the data section found.
struct ScanResult {
  Header header;
  Summary summary;  ///< reconstructed: schemas, channels, chunk indexes, statistics, metadata
  std::uint64_t data_end_offset = 0;       ///< offset of Data End (0: none found)
  std::uint64_t last_complete_offset = 0;  ///< end of the last complete top-level record
  bool truncated = false;
  std::uint64_t truncated_at = 0;
  std::string truncation_detail;
  std::uint64_t loose_message_count = 0;  ///< Message records outside chunks
  bool data_crc_checked = false;          ///< Data End carried a CRC and it matched
  /// With ReaderOptions::skip_corrupt_chunks: the chunks left out (the data section CRC then
  /// cannot match and is not an error).
  std::vector<SkippedChunk> skipped_chunks;
  /// With ReaderOptions::skip_corrupt_chunks: Chunk records whose length field disagreed with
  /// the chunk's own fields and that were read by their fields (the data CRC then cannot match).
  std::uint64_t chunk_lengths_corrected = 0;
};

/// Called per message; return false to stop early.
using MessageCallback = std::function<bool(const MessageView&)>;

class Reader {
 public:
  Reader();
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;
  Reader(Reader&&) noexcept;
  Reader& operator=(Reader&&) noexcept;

  /// Opens a file and checks the leading magic and Header.
  Status open(const std::filesystem::path& path, const ReaderOptions& options = {});
  /// Reads from memory the caller keeps alive (used by tests and the fuzzer).
  Status open_memory(std::span<const std::byte> bytes, const ReaderOptions& options = {});

  const Header& header() const;
  std::uint64_t file_size() const;

  /// Fast path: trailing magic, Footer, summary section (with its CRC). Fails, naming the
  /// offset, when the file has no footer/summary or it is corrupt.
  Status read_summary();
  bool has_summary() const;
  /// The summary read by read_summary() or rebuilt by scan().
  const Summary& summary() const;
  const Footer& footer() const;

  /// Walks every record of the data section from the start, checking all CRCs. Messages go to
  /// `on_message` in file order when it is set. With `allow_truncated`, an incomplete tail
  /// ends the scan with success and `result.truncated` set.
  Status scan(ScanResult& result, bool allow_truncated = false,
              const MessageCallback& on_message = {});

  /// The Metadata record of one of summary().metadata_indexes (read_summary() or scan() first).
  Status read_metadata(const MetadataIndex& index, Metadata& out);

  /// Messages in log-time order (ties: file order), through the chunk indexes; falls back
  /// to a linear scan when the summary is missing (see ReadOptions).
  Status read_messages(const MessageCallback& on_message, const ReadOptions& options = {},
                       ReadReport* report = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct RepairReport {
  bool input_had_summary = false;
  bool input_truncated = false;
  std::uint64_t input_truncated_at = 0;
  std::uint64_t chunks_kept = 0;
  std::uint64_t messages_kept = 0;
  std::uint64_t bytes_dropped = 0;  ///< input bytes after the last record kept
  /// Why the scan stopped early (truncation, CRC mismatch, ...); empty when it reached Data End.
  std::string stopped_because;
  /// Chunks left out because their content is corrupt (the records after them are kept).
  std::vector<SkippedChunk> skipped_chunks;
  /// Chunks kept whose length field was corrupt: written with the length their fields give.
  std::uint64_t chunk_lengths_corrected = 0;
  /// The input's own summary's message count, when it had a valid one.
  std::uint64_t input_summary_messages = 0;
  /// Where the result is: `output`, or `<output>.repaired.mcap` when it would have replaced
  /// the input but is not complete.
  std::filesystem::path written_to;
};

/// Rewrites `input` into `output` with fresh Message Indexes, Data End, summary and footer,
/// from a linear scan: keeps every complete, valid record up to the first incomplete one;
/// a chunk whose framing is intact but whose content is corrupt is left out (reported) and the
/// scan goes on. The result is read back (summary, CRCs, message count) before it is kept.
/// `output` may equal `input`: the input is then replaced only when the result is complete
/// (no chunk left out; as many messages as the input's valid summary counts) and verified;
/// otherwise the result stays at `<output>.repaired.mcap` (report.written_to), the input is
/// untouched and the status says so (StatusCode::incomplete).
Status repair_file(const std::filesystem::path& input, const std::filesystem::path& output,
                   RepairReport& report);

}  // namespace avs::mcap
