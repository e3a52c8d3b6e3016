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

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"

namespace avs::mcap {

struct ReaderOptions {
  /// Refuse chunks whose uncompressed size exceeds this (protects against hostile sizes).
  std::uint64_t max_chunk_uncompressed_bytes = 1ull << 30;
  /// Refuse any single record larger than this.
  std::uint64_t max_record_bytes = 2ull << 30;
  bool verify_chunk_crc = true;
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
};

/// Rewrites `input` into `output` with fresh Message Indexes, Data End, summary and footer,
/// from a linear scan: keeps every complete, valid record up to the first incomplete or corrupt
/// one (everything after it is dropped and reported).
/// `output` may equal `input` (written to a temporary file, then renamed).
Status repair_file(const std::filesystem::path& input, const std::filesystem::path& output,
                   RepairReport& report);

}  // namespace avs::mcap
