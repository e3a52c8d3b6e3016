// What the components of a container have published on each DDS writer, counted, and sent on
// /avs/writer_counts (avs_msgs/WriterCounts) every 0.1 s of the container's clock and once as
// it stops (issue 20 section 6). A recorder in another process reconciles what it received
// against these counts, so it can report loss that DDS never reports: a reliable KEEP_LAST
// writer that overwrites samples a slow reader has not acknowledged moves that reader past
// them without a SAMPLE_LOST (Cyclone 0.10.2, docs/bag.md "Loss accounting").
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "avs/runtime/dds.hpp"
#include "avs/runtime/time.hpp"

namespace avs::runtime {

/// Counts the samples published on one DDS writer. Each one sent to DDS gets a source
/// timestamp strictly greater than the previous one (the wall clock, nudged by 1 ns where two
/// writes read the same time), and the count is taken under the same lock as the write, so a
/// cut (published, last_source_time_ns) says exactly which samples were published up to the
/// one sent with that timestamp. Samples not sent (no reader in another process then) are
/// counted too: for a recorder that was unmatched meanwhile they are missing all the same.
class WriterTally {
 public:
  struct Cut {
    std::uint64_t published = 0;
    std::int64_t last_source_time_ns = 0;  ///< 0: nothing sent yet
  };

  /// Counts `sample` and, when `send`, writes it to DDS.
  void publish(dds::Writer& writer, const void* sample, bool send);
  Cut cut() const;

 private:
  mutable std::mutex mutex_;
  std::uint64_t published_ = 0;
  Cut cut_;  ///< at the last sample sent
};

/// The /avs/writer_counts writer of one container.
class WriterCountsPublisher {
 public:
  struct Entry {
    const dds::Writer* writer;
    std::string ros_topic;
    const WriterTally* tally;
  };

  WriterCountsPublisher(const dds::Participant& participant, std::string container_name,
                        std::vector<Entry> writers);
  /// Publishes every writer's cut (those that wrote anything), when a reader is matched.
  void publish(Time stamp);

 private:
  std::string container_name_;
  std::vector<Entry> writers_;
  std::vector<std::array<std::uint8_t, 16>> gids_;
  dds::Topic topic_;
  dds::Writer writer_;
};

}  // namespace avs::runtime
