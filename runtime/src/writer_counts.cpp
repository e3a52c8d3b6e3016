#include "writer_counts.hpp"

#include <algorithm>
#include <utility>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/qos.hpp"
#include "avs/runtime/ros_discovery.hpp"
#include "avs/runtime/sample.hpp"

namespace avs::runtime {

void WriterTally::publish(dds::Writer& writer, const void* sample, bool send) {
  std::lock_guard lock(mutex_);
  ++published_;
  if (!send) return;
  // Strictly increasing, so that no later sample shares the cut's timestamp.
  const std::int64_t now_ns = dds_time();
  const std::int64_t stamp_ns = std::max(now_ns, cut_.last_source_time_ns + 1);
  const dds_return_t rc = dds_write_ts(writer.get(), sample, stamp_ns);
  if (rc < 0) check_dds(rc, "write to " + writer.topic_name());  // no message made per sample
  cut_ = {published_, stamp_ns};
}

WriterTally::Cut WriterTally::cut() const {
  std::lock_guard lock(mutex_);
  return cut_;
}

namespace {

QosProfile counts_qos() {
  QosProfile q;  // reliable, volatile, keep last 10: a recorder needs any two reports
  return q;
}

}  // namespace

WriterCountsPublisher::WriterCountsPublisher(const dds::Participant& participant,
                                             std::string container_name, std::vector<Entry> writers)
    : container_name_(std::move(container_name)),
      writers_(std::move(writers)),
      topic_(participant, msg::TypeSupport<msgs::avs_msgs::WriterCounts>::descriptor(),
             "rt/avs/writer_counts", counts_qos()),
      writer_(participant, topic_, counts_qos()) {
  for (const Entry& e : writers_) gids_.push_back(gid_of(e.writer->get()));
}

void WriterCountsPublisher::publish(Time stamp) {
  if (writer_.matched_readers() == 0) return;
  auto sample = make_sample<msgs::avs_msgs::WriterCounts>();
  to_ros_time(stamp, sample->header.stamp);
  set_string(sample->header.frame_id, container_name_);
  std::vector<std::pair<std::size_t, WriterTally::Cut>> cuts;
  for (std::size_t i = 0; i < writers_.size(); ++i) {
    const WriterTally::Cut cut = writers_[i].tally->cut();
    if (cut.last_source_time_ns > 0) cuts.emplace_back(i, cut);
  }
  if (cuts.empty()) return;
  resize_sequence(sample->writers, static_cast<std::uint32_t>(cuts.size()));
  for (std::size_t k = 0; k < cuts.size(); ++k) {
    const auto& [i, cut] = cuts[k];
    auto& out = sample->writers._buffer[k];
    std::copy(gids_[i].begin(), gids_[i].end(), std::begin(out.writer_gid));
    set_string(out.topic, writers_[i].ros_topic);
    out.samples = cut.published;
    out.last_source_timestamp_ns = cut.last_source_time_ns;
  }
  writer_.write(sample.get());
}

}  // namespace avs::runtime
