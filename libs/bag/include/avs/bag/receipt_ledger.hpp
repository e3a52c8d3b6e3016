// Reconciles what a recorder received from each DDS writer with the writer's own counts
// (avs_msgs/WriterCounts on /avs/writer_counts, issue 20 section 6): the samples it never got,
// whether or not DDS reported them. No I/O: the recorder feeds it samples and reports.
//
// A writer's report is a cut (published, last_source_time_ns): `published` samples up to and
// including the one stamped last_source_time_ns (source timestamps strictly increase per
// writer). The window of reconciliation runs between two cuts whose last sample the recorder
// itself received: the first such cut and the latest. Between them the components published
// end.published - start.published samples on the writer (those sent to DDS with a source
// timestamp in (start, end], and those not sent because no other process was matched at the
// time: a recorder that dropped out of discovery lacks them too); those the recorder did not
// receive are missing. Anchoring both ends on received samples keeps
// out what the recorder could never have had (written before its reader was matched, or
// after it stopped), and lets anyone check the figure from the file: the two anchor samples
// are in it, with their publish times.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <unordered_set>
#include <vector>

namespace avs::bag {

using WriterGid = std::array<std::uint8_t, 16>;

struct WriterCut {
  std::uint64_t published =
      0;  ///< samples published up to and including the one at last_source_time_ns
  std::int64_t last_source_time_ns = 0;
};

/// The reconciliation of one writer.
struct WriterReconciliation {
  bool reconciled = false;     ///< a window exists (two anchored cuts, the later one newer)
  std::uint64_t received = 0;  ///< every sample received from the writer
  std::uint64_t expected = 0;  ///< published within the window
  std::uint64_t received_in_window = 0;
  std::uint64_t missing = 0;     ///< expected - received_in_window
  std::uint64_t duplicates = 0;  ///< received_in_window above expected (never seen; kept visible)
  std::int64_t window_start_ns = 0;  ///< source time of the start anchor (excluded)
  std::int64_t window_end_ns = 0;    ///< source time of the end anchor (included)
  std::uint64_t reports = 0;         ///< cuts reported by the writer
};

class ReceiptLedger {
 public:
  /// A sample from `writer` with source timestamp `source_time_ns`.
  void received(const WriterGid& writer, std::int64_t source_time_ns);
  /// A cut reported by `writer`.
  void reported(const WriterGid& writer, const WriterCut& cut);
  /// Every writer seen (sample or report), with its reconciliation so far.
  std::map<WriterGid, WriterReconciliation> results() const;
  /// Cuts reported by `writer` so far (0 for a writer never heard of).
  std::uint64_t reports(const WriterGid& writer) const;
  /// Per writer: samples received and the newest source time among them (what a recorder
  /// tells a lockstep graph it has, /avs/recorder_progress). Cheap.
  struct Progress {
    std::uint64_t received = 0;
    std::int64_t newest_source_time_ns = 0;
  };
  std::map<WriterGid, Progress> progress() const;

 private:
  struct Writer {
    std::uint64_t received = 0;
    std::int64_t newest = 0;
    std::uint64_t reports = 0;
    std::optional<WriterCut> start, end;
    /// Received since the start anchor, with a source time after it.
    std::uint64_t after_start = 0;
    /// Source times of recent receipts (for anchoring cuts and for the samples after the end
    /// anchor), oldest first; bounded.
    std::deque<std::int64_t> recent;
    std::unordered_set<std::int64_t> recent_set;
    /// Cuts whose last sample has not arrived yet (it may still, after the report); bounded.
    std::vector<WriterCut> pending;
  };
  void anchor(Writer& w, const WriterCut& cut);

  std::map<WriterGid, Writer> writers_;
};

}  // namespace avs::bag
