#include "recorder_acks.hpp"

#include <algorithm>
#include <chrono>
#include <set>
#include <string_view>
#include <thread>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/ros_discovery.hpp"

namespace avs::runtime {

namespace {

QosProfile progress_qos() {
  QosProfile q;
  q.depth = 64;  // several recorders' updates between two takes
  return q;
}

}  // namespace

RecorderAcks::RecorderAcks(const dds::Participant& participant, std::vector<Watched> writers,
                           const Logger& log, Duration timeout)
    : progress_topic_(participant, msg::TypeSupport<msgs::avs_msgs::WriterCounts>::descriptor(),
                      "rt/avs/recorder_progress", progress_qos()),
      progress_reader_(participant, progress_topic_, progress_qos()),
      waitset_(participant),
      progress_condition_(check_dds(dds_create_readcondition(progress_reader_.get(), DDS_ANY_STATE),
                                    "read condition on rt/avs/recorder_progress")),
      log_(log),
      timeout_(timeout) {
  waitset_.attach(progress_condition_.get(), 1);
  for (const Watched& w : writers) {
    Writer entry{w};
    entry.gid = gid_of(w.writer->get());
    writers_.push_back(entry);
  }
}

bool RecorderAcks::has_recorder(const dds::Writer& writer) const {
  constexpr std::size_t kMax = 256;
  dds_instance_handle_t handles[kMax];
  const dds_return_t n = dds_get_matched_subscriptions(writer.get(), handles, kMax);
  if (n < 0) return false;
  for (dds_return_t i = 0; i < std::min<dds_return_t>(n, kMax); ++i) {
    dds_builtintopic_endpoint_t* ep = dds_get_matched_subscription_data(writer.get(), handles[i]);
    if (ep == nullptr) continue;
    void* data = nullptr;
    size_t size = 0;
    bool recorder = false;
    if (ep->qos != nullptr && dds_qget_userdata(ep->qos, &data, &size) && data != nullptr) {
      recorder = std::string_view(static_cast<const char*>(data), size) == dds::kRecorderUserData;
    }
    dds_free(data);
    dds_builtintopic_free_endpoint(ep);
    if (recorder) return true;
  }
  return false;
}

void RecorderAcks::take_progress() {
  constexpr int kBatch = 16;
  for (;;) {
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = dds_take(progress_reader_.get(), samples, infos, kBatch, kBatch);
    if (n <= 0) return;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* progress = static_cast<const avs_msgs_msg_dds__WriterCounts_*>(samples[i]);
      for (std::uint32_t k = 0; k < progress->writers._length; ++k) {
        const auto& w = progress->writers._buffer[k];
        Gid gid;
        std::copy(std::begin(w.writer_gid), std::end(w.writer_gid), gid.begin());
        std::int64_t& newest = newest_[{infos[i].publication_handle, gid}];
        newest = std::max(newest, w.last_source_timestamp_ns);
      }
    }
    dds_return_loan(progress_reader_.get(), samples, n);
    if (n < kBatch) return;
  }
}

bool RecorderAcks::caught_up(const Gid& gid, std::int64_t source_ns) {
  // Recorders that are gone no longer count.
  constexpr std::size_t kMax = 64;
  dds_instance_handle_t handles[kMax];
  const dds_return_t n = dds_get_matched_publications(progress_reader_.get(), handles, kMax);
  const std::set<dds_instance_handle_t> live(
      handles, handles + std::clamp<dds_return_t>(n, 0, static_cast<dds_return_t>(kMax)));
  bool any = false;
  for (const auto& [key, newest] : newest_) {
    if (key.second != gid || live.count(key.first) == 0) continue;
    any = true;
    if (newest < source_ns) return false;
  }
  return any;
}

bool RecorderAcks::wait_for_a_recorder(Duration timeout,
                                       const std::function<bool()>& stop_requested) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    for (const Writer& w : writers_) {
      if (!w.watched.reliable) continue;
      dds_publication_matched_status_t status{};
      if (dds_get_publication_matched_status(w.watched.writer->get(), &status) < 0) continue;
      if (status.current_count > 0 && has_recorder(*w.watched.writer)) return true;
    }
    if (stop_requested() || std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void RecorderAcks::wait(const std::function<bool()>& stop_requested) {
  take_progress();
  // One deadline for the whole step: a hung recorder costs `timeout` per step, not per writer.
  const auto deadline = std::chrono::steady_clock::now() + timeout_;
  for (Writer& w : writers_) {
    if (!w.watched.reliable) continue;
    const dds::Writer& writer = *w.watched.writer;
    dds_publication_matched_status_t status{};
    if (dds_get_publication_matched_status(writer.get(), &status) < 0) continue;
    if (status.total_count != w.matched_total || status.current_count != w.matched_current) {
      w.matched_total = status.total_count;
      w.matched_current = status.current_count;
      const bool was = w.recorder;
      w.recorder = status.current_count > 0 && has_recorder(writer);
      if (w.recorder && !was) {
        w.caught_up = w.watched.tally->cut().published;
        log_.info("a recorder reads ", writer.topic_name(),
                  ": lockstep waits for it rather than outrun it");
      }
    }
    if (!w.recorder) continue;
    const WriterTally::Cut cut = w.watched.tally->cut();
    const std::uint64_t threshold = std::max<std::uint32_t>(1, w.watched.history_depth / 2);
    if (cut.published - w.caught_up < threshold) continue;
    if (caught_up(w.gid, cut.last_source_time_ns)) {
      w.caught_up = cut.published;
      continue;
    }
    bool done = false;
    while (!done && !stop_requested()) {
      const auto left = deadline - std::chrono::steady_clock::now();
      if (left <= Duration::zero()) break;
      dds_attach_t triggered[2];
      waitset_.wait(triggered, 2,
                    std::min<std::int64_t>(std::chrono::duration_cast<Duration>(left).count(),
                                           DDS_MSECS(10)));
      take_progress();
      done = caught_up(w.gid, cut.last_source_time_ns);
    }
    w.caught_up = cut.published;  // caught up, or given up on: time goes on
    if (!done && !stop_requested()) {
      ++timeouts_;
      log_.warn("a recorder of ", writer.topic_name(), " did not catch up within ",
                static_cast<double>(timeout_.count()) * 1e-9,
                " s: time goes on, it may lose samples and will report them (", timeouts_,
                " time(s) so far)");
    }
  }
}

}  // namespace avs::runtime
