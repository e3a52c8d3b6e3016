// A lockstep container waits for recorders (issue 20 section 6). A reliable KEEP_LAST writer
// overwrites the samples a slow reader has not acknowledged, and a lockstep graph runs as fast
// as it can, so `avs bag record` in another process fell behind the closed loop and lost
// samples that DDS does not report. Lockstep time is the graph's own: it can afford to wait.
// Before each step, every writer with a recorder among its matched readers (a reader whose
// USER_DATA is kRecorderUserData) that has written half its history depth since the recorder
// last caught up waits until the recorder says it has received its newest sample
// (/avs/recorder_progress: per writer, the newest source timestamp it got), at most `timeout`:
// a recorder that hangs costs time, never the graph. Received implies acknowledged or given
// up by DDS, and the recorder says so within a take, where DDS's own acknowledgements wait
// for the writer's next heartbeat (up to 100 ms: 227 s instead of 16 s for 3 s of the closed
// loop with dds_wait_for_acks). Wall-clock graphs cannot wait; there the recorder's
// reconciliation with /avs/writer_counts counts what it lost.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "avs/runtime/dds.hpp"
#include "avs/runtime/logger.hpp"
#include "avs/runtime/time.hpp"
#include "writer_counts.hpp"

namespace avs::runtime {

class RecorderAcks {
 public:
  struct Watched {
    const dds::Writer* writer;
    const WriterTally* tally;
    std::uint32_t history_depth;
    bool reliable;  ///< best-effort writers are not waited for: a lost sample never arrives
  };

  RecorderAcks(const dds::Participant& participant, std::vector<Watched> writers, const Logger& log,
               Duration timeout);
  /// Before a lockstep step: waits where a recorder would otherwise lose samples, at most
  /// `timeout` in all, and not once `stop_requested` says so.
  void wait(const std::function<bool()>& stop_requested);
  /// Before the first step (ClockSpec::recorder_start_timeout_s): waits until a recorder has
  /// matched one of the reliable writers, at most `timeout`; whether one did.
  bool wait_for_a_recorder(Duration timeout, const std::function<bool()>& stop_requested) const;
  /// Waits that ran out of time (the recorder then loses samples, and reports them).
  std::uint64_t timeouts() const { return timeouts_; }

 private:
  struct Writer {
    Watched watched;
    std::uint32_t matched_total = 0;  ///< publication matched total_count last looked at
    std::uint32_t matched_current = 0;
    bool recorder = false;        ///< a recorder is among the matched readers
    std::uint64_t caught_up = 0;  ///< samples written when the recorders last had them all
    std::array<std::uint8_t, 16> gid{};
  };
  using Gid = std::array<std::uint8_t, 16>;
  bool has_recorder(const dds::Writer& writer) const;
  /// Takes the recorders' progress into `newest_`.
  void take_progress();
  /// Whether every live recorder that reported on `gid` has its sample stamped `source_ns`
  /// (false when none has reported on it yet).
  bool caught_up(const Gid& gid, std::int64_t source_ns);

  std::vector<Writer> writers_;
  dds::Topic progress_topic_;
  dds::Reader progress_reader_;
  dds::WaitSet waitset_;
  dds::Entity progress_condition_;
  /// (recorder's progress writer, our writer) -> newest source time it has.
  std::map<std::pair<dds_instance_handle_t, Gid>, std::int64_t> newest_;
  const Logger& log_;
  Duration timeout_;
  std::uint64_t timeouts_ = 0;
};

}  // namespace avs::runtime
