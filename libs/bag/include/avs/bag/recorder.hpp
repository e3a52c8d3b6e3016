// Recorder: discovers topics as their publishers appear, reads them as serialised CDR and
// writes every sample, untouched, to MCAP (`avs bag record`, docs/bag.md).
//
// Threads: a reader thread (discovery, readers, taking samples into a bounded queue that
// holds Cyclone's serdata references, so a sample is never copied before it reaches the
// chunk buffer) and a writer thread (queue -> avs::mcap::Writer, whose own thread compresses
// and writes chunks). Every sample the recorder knows it did not store is counted, per
// topic and per cause: DDS sample-lost, DDS sample-rejected, its own queue overflow; and
// what the recorder received from each writer is reconciled with the writer's own count
// (/avs/writer_counts, published by every avs container), which also finds the samples DDS
// never reports lost (issue 20 section 6).
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "avs/mcap/records.hpp"

namespace avs::bag {

struct RecordOptions {
  bool all = false;                 ///< -a: every topic
  std::vector<std::string> topics;  ///< ROS names ("/chatter", "chatter") or DDS names
  std::string include_regex;        ///< -e: ROS names matching (std::regex_search)
  std::string exclude_regex;        ///< -x: ROS names matching are never recorded
  std::filesystem::path output;
  mcap::Compression compression = mcap::Compression::zstd;
  int compression_level = 1;
  std::uint64_t chunk_size_bytes = 4u << 20;
  /// Split: start a new file (`<stem>_1.mcap`, `_2`, ...) once a file reaches this size or
  /// covers this duration of log time (0: never).
  std::uint64_t max_size_bytes = 0;
  double max_duration_s = 0;
  /// Bytes of samples waiting for the writer; a sample that does not fit is dropped and
  /// counted (queue overflow).
  std::uint64_t queue_bytes = 1ull << 30;
  /// Close the open chunk at least this often, so a killed recorder loses at most this much.
  double flush_interval_s = 1.0;
  int domain = 0;
  std::string partition;  ///< DDS partition of the readers/writers; empty: default
};

/// Counters of one topic (cumulative).
struct TopicCounters {
  std::string topic;  ///< ROS name
  std::string type;   ///< ROS type name
  std::string qos;    ///< what the reader requested
  std::uint64_t publishers = 0;
  std::uint64_t received = 0;
  std::uint64_t written = 0;
  std::uint64_t bytes = 0;  ///< serialised bytes received
  std::uint64_t dds_lost = 0;
  std::uint64_t dds_rejected = 0;
  std::uint64_t queue_dropped = 0;
  /// Received but not in the file because writing it failed (disk full): the failing
  /// message, those queued behind it and those of the chunk that was being filled.
  std::uint64_t write_failed = 0;
  std::uint32_t incompatible_writers = 0;  ///< writers not matched (QoS): not recorded at all
  std::string skipped_because;             ///< non-empty: the topic is not recorded
  /// Reconciliation with the writers' own counts (/avs/writer_counts, receipt_ledger.hpp):
  /// writers with a window, writers without (not avs components, or seen too briefly).
  std::uint32_t writers_reconciled = 0;
  std::uint32_t writers_unreconciled = 0;
  std::uint64_t expected_in_window = 0;  ///< written by reconciled writers inside their windows
  std::uint64_t missing = 0;  ///< of those, never received (whether DDS reported them or not)
  /// Samples that never reached the recorder: the writers' count where every writer has one
  /// (DDS's own statuses miss overwritten samples and count rejected ones that were resent);
  /// DDS's sample-lost and sample-rejected counts where none has; the larger of the two when
  /// some have.
  std::uint64_t not_received() const {
    if (writers_reconciled == 0) return dds_lost + dds_rejected;
    if (writers_unreconciled == 0) return missing;
    return std::max(missing, dds_lost + dds_rejected);
  }
  std::uint64_t lost() const { return not_received() + queue_dropped + write_failed; }
};

struct RecorderStatus {
  std::vector<TopicCounters> topics;  ///< sorted by topic
  std::uint64_t received = 0;
  std::uint64_t written = 0;
  std::uint64_t bytes_received = 0;
  std::uint64_t lost = 0;
  std::uint64_t queue_bytes = 0;  ///< waiting now
  std::uint64_t queue_bytes_peak = 0;
  std::uint64_t file_bytes = 0;  ///< written to the current file so far
  std::vector<std::filesystem::path> files;
  bool finished = false;  ///< stopped by itself (max duration reached or an error)
  std::string error;      ///< why it stopped, when it failed
};

class Recorder {
 public:
  /// Checks the options (regexes, output directory) and creates the DDS participant; throws
  /// runtime::Error naming the problem.
  explicit Recorder(RecordOptions options);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Opens the first file and starts the threads.
  void start();
  /// Takes what DDS still holds, writes the queue out and closes the file(s) cleanly.
  /// Throws runtime::Error when the file could not be written or closed.
  void stop();
  RecorderStatus status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Human-readable end-of-recording report: per topic counts and every known loss.
std::string format_record_report(const RecorderStatus& status);

}  // namespace avs::bag
