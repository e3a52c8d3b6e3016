#include "avs/bag/recorder.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "avs/bag/file_split.hpp"
#include "avs/bag/qos_yaml.hpp"
#include "avs/bag/receipt_ledger.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/mcap/writer.hpp"
#include "avs/msg/type_registry.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/runtime/topic_name.hpp"
#include "avs_msgs.h"

namespace avs::bag {

namespace {

using runtime::Error;
namespace dds = runtime::dds;

std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// "/chatter", "chatter" and "rt/chatter" all name the ROS topic "/chatter".
std::string ros_topic_of(const std::string& name) {
  if (name.rfind("rt/", 0) == 0) return runtime::from_dds_topic_name(name);
  return runtime::resolve_topic_name("/", name);
}

/// Stopping: how long to wait for every reporting writer's next count (reports come every
/// 0.1 s), then how long to keep taking for the samples those counts name.
constexpr auto kFinalReportWait = std::chrono::milliseconds(500);
constexpr auto kFinalSampleGrace = std::chrono::milliseconds(100);

}  // namespace

/// One recorded topic: created by the reader thread, read by everyone (counters atomic).
struct RecordedTopic {
  std::string dds_topic;
  std::string ros_topic;
  std::string dds_type;
  std::string ros_type;
  std::string schema_text;
  std::unique_ptr<dds::RawReader> reader;  // null when skipped
  std::string skipped_because;
  std::string requested_qos;
  std::vector<dds::EndpointQos> offered;  // guarded by Impl::topics_mutex
  std::set<std::array<std::uint8_t, 16>> writers;
  std::atomic<std::uint64_t> received{0}, written{0}, bytes{0}, dds_lost{0}, dds_rejected{0},
      queue_dropped{0}, write_failed{0};
  std::uint64_t written_to_open_file = 0;  // writer thread only
  std::atomic<std::uint32_t> incompatible{0};
  /// Receipts per writer against the writers' counts; the writer of each publication handle.
  mutable std::mutex ledger_mutex;
  ReceiptLedger ledger;
  std::map<dds_instance_handle_t, WriterGid> writer_of;  // reader thread only

  /// The counters of the report (call with the recorder's topics_mutex held).
  TopicCounters counters() const {
    TopicCounters c;
    c.topic = ros_topic;
    c.type = ros_type;
    c.qos = requested_qos;
    c.publishers = writers.size();
    c.received = received;
    c.written = written;
    c.bytes = bytes;
    c.dds_lost = dds_lost;
    c.dds_rejected = dds_rejected;
    c.queue_dropped = queue_dropped;
    c.write_failed = write_failed;
    c.incompatible_writers = incompatible;
    c.skipped_because = skipped_because;
    std::lock_guard lock(ledger_mutex);
    for (const auto& [gid, r] : ledger.results()) {
      if (!r.reconciled) {
        ++c.writers_unreconciled;
        continue;
      }
      ++c.writers_reconciled;
      c.expected_in_window += r.expected;
      c.missing += r.missing;
    }
    return c;
  }
};

namespace {

std::string hex(const WriterGid& gid) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (std::uint8_t b : gid) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

}  // namespace

struct QueuedSample {
  RecordedTopic* topic;
  ddsi_serdata* data;  // one reference
  std::uint64_t size;
  mcap::Timestamp log_time;
  mcap::Timestamp publish_time;
};

struct Recorder::Impl {
  RecordOptions options;
  std::optional<std::regex> include, exclude;
  std::set<std::string> wanted;  // ROS names
  dds::Participant participant;
  std::unique_ptr<dds::PublicationDiscovery> discovery;
  std::unique_ptr<dds::WaitSet> waitset;
  std::vector<dds::Entity> conditions;
  /// The writers' counts (/avs/writer_counts), read by the reader thread.
  dds::Entity counts_topic, counts_reader;
  /// What it has received, per writer (/avs/recorder_progress), for lockstep graphs that wait
  /// for it (runtime/src/recorder_acks.hpp); sent when it changed.
  dds::Entity progress_topic, progress_writer;
  std::map<std::pair<RecordedTopic*, WriterGid>, std::uint64_t> progress_sent;
  std::chrono::steady_clock::time_point progress_sent_at{};
  bool progress_failed = false;

  mutable std::mutex topics_mutex;
  std::map<std::string, std::unique_ptr<RecordedTopic>> topics;  // by DDS name

  std::mutex queue_mutex;
  std::condition_variable queue_changed;
  std::deque<QueuedSample> queue;
  std::atomic<std::uint64_t> queued_bytes{0}, queued_peak{0};
  bool readers_done = false;  // guarded by queue_mutex

  std::atomic<bool> stop_reading{false};
  std::atomic<bool> finished{false};
  mutable std::mutex error_mutex;
  std::string error;

  // Writer thread state.
  mcap::Writer writer;
  int file_index = 0;
  std::vector<std::filesystem::path> files;  // guarded by error_mutex
  std::map<RecordedTopic*, mcap::ChannelId> channels;
  mcap::Timestamp file_start = 0;
  std::atomic<std::uint64_t> file_bytes{0};

  std::thread reader_thread, writer_thread;
  bool started = false;

  explicit Impl(RecordOptions o)
      : options(std::move(o)), participant(options.domain, options.partition) {}

  void fail(const std::string& what) {
    {
      std::lock_guard lock(error_mutex);
      if (error.empty()) error = what;
    }
    finished = true;
    stop_reading = true;
    waitset->wake();
  }

  bool selected(const std::string& dds_topic, const std::string& ros_topic) const {
    if (exclude && std::regex_search(ros_topic, *exclude)) return false;
    // -a records ROS topics (rt/...), as `ros2 bag record -a`: not the services' rq/ and rr/
    // samples (the parameter services), nor ros_discovery_info.
    if (options.all) return dds_topic.rfind("rt/", 0) == 0;
    if (wanted.count(ros_topic) != 0) return true;
    return include && std::regex_search(ros_topic, *include);
  }

  void add_publication(const dds::DiscoveredPublication& p) {
    const std::string ros_topic = runtime::from_dds_topic_name(p.topic);
    std::lock_guard lock(topics_mutex);
    auto it = topics.find(p.topic);
    if (it != topics.end()) {
      RecordedTopic& t = *it->second;
      if (t.writers.insert(p.key).second) t.offered.push_back(p.qos);
      return;
    }
    if (!selected(p.topic, ros_topic)) return;
    auto t = std::make_unique<RecordedTopic>();
    t->dds_topic = p.topic;
    t->ros_topic = ros_topic;
    t->dds_type = p.type_name;
    t->ros_type = introspection::ros_type_name(p.type_name);
    t->writers.insert(p.key);
    t->offered.push_back(p.qos);
    const msg::TypeEntry* type = msg::find_type(p.type_name);
    if (type == nullptr) {
      t->skipped_because = "type " + p.type_name + " is not known to this build";
    } else {
      try {
        t->schema_text =
            introspection::ros2msg_definition(introspection::built_in_types(), p.type_name);
        // Reliable only when the first publisher is (a reliable request does not match a best
        // effort writer); transient local likewise. KEEP_ALL: DDS never overwrites a sample
        // the recorder has not taken; what it cannot accept is reported as rejected.
        dds::EndpointQos q;
        q.reliable = p.qos.reliable;
        q.transient_local = p.qos.transient_local;
        q.keep_all = true;
        t->requested_qos = q.describe();
        // Marked as a recorder's, a lockstep graph's writers wait for it: only when it can
        // tell them what it has (its progress writer exists), or they would wait in vain.
        t->reader = std::make_unique<dds::RawReader>(
            participant, *type, p.topic, q,
            progress_writer ? dds::kRecorderUserData : std::string_view{});
        dds::Entity condition(
            runtime::check_dds(dds_create_readcondition(t->reader->get(), DDS_ANY_STATE),
                               "read condition on " + p.topic));
        waitset->attach(condition.get(), static_cast<dds_attach_t>(conditions.size() + 2));
        conditions.push_back(std::move(condition));
      } catch (const std::exception& e) {
        t->reader.reset();
        t->skipped_because = e.what();
      }
    }
    if (!t->skipped_because.empty()) {
      std::fprintf(stderr, "avs bag record: NOT recording %s: %s\n", ros_topic.c_str(),
                   t->skipped_because.c_str());
    }
    topics.emplace(p.topic, std::move(t));
  }

  void enqueue(RecordedTopic& t, ddsi_serdata* data, const dds_sample_info_t& info,
               std::uint64_t now) {
    const std::uint64_t size = ddsi_serdata_size(data);
    t.received.fetch_add(1, std::memory_order_relaxed);
    t.bytes.fetch_add(size, std::memory_order_relaxed);
    // Received, whether or not the queue has room: a drop is counted as queue_dropped, not
    // again as missing, and a lockstep graph is told it arrived.
    note_receipt(t, info);
    std::lock_guard lock(queue_mutex);
    if (queued_bytes.load(std::memory_order_relaxed) + size > options.queue_bytes &&
        !queue.empty()) {
      t.queue_dropped.fetch_add(1, std::memory_order_relaxed);
      ddsi_serdata_unref(data);
      return;
    }
    const std::uint64_t publish =
        info.source_timestamp > 0 ? static_cast<std::uint64_t>(info.source_timestamp) : now;
    queue.push_back({&t, data, size, now, publish});
    const std::uint64_t q = queued_bytes.fetch_add(size, std::memory_order_relaxed) + size;
    if (q > queued_peak.load(std::memory_order_relaxed))
      queued_peak.store(q, std::memory_order_relaxed);
    queue_changed.notify_one();
  }

  /// Counts the sample against its writer (reconciled with the writer's reports).
  void note_receipt(RecordedTopic& t, const dds_sample_info_t& info) {
    auto it = t.writer_of.find(info.publication_handle);
    if (it == t.writer_of.end()) {
      WriterGid gid{};
      if (dds_builtintopic_endpoint_t* ep =
              dds_get_matched_publication_data(t.reader->get(), info.publication_handle)) {
        std::copy(std::begin(ep->key.v), std::end(ep->key.v), gid.begin());
        dds_builtintopic_free_endpoint(ep);
      }
      // A writer gone before its first sample was taken keeps the all-zero GUID: its samples
      // are received but never reconciled (no report names that GUID).
      it = t.writer_of.emplace(info.publication_handle, gid).first;
    }
    std::lock_guard lock(t.ledger_mutex);
    t.ledger.received(it->second, info.source_timestamp);
  }

  /// Takes the writers' counts and hands each to the topic it counts.
  void take_counts() {
    constexpr int kBatch = 16;
    for (;;) {
      void* samples[kBatch] = {};
      dds_sample_info_t infos[kBatch];
      const dds_return_t n = dds_take(counts_reader.get(), samples, infos, kBatch, kBatch);
      if (n <= 0) break;
      {
        std::lock_guard lock(topics_mutex);
        for (int i = 0; i < n; ++i) {
          if (!infos[i].valid_data) continue;
          const auto* counts = static_cast<const avs_msgs_msg_dds__WriterCounts_*>(samples[i]);
          for (std::uint32_t k = 0; k < counts->writers._length; ++k) {
            const auto& w = counts->writers._buffer[k];
            std::string dds_name;
            try {
              dds_name = runtime::to_dds_topic_name(runtime::get_string(w.topic));
            } catch (const std::exception&) {
              continue;  // not a topic name (not from an avs container): nothing to reconcile
            }
            auto it = topics.find(dds_name);
            if (it == topics.end() || !it->second->reader) continue;
            WriterGid gid;
            std::copy(std::begin(w.writer_gid), std::end(w.writer_gid), gid.begin());
            std::lock_guard ledger_lock(it->second->ledger_mutex);
            it->second->ledger.reported(gid, {w.samples, w.last_source_timestamp_ns});
          }
        }
      }
      dds_return_loan(counts_reader.get(), samples, n);
      if (n < kBatch) break;
    }
  }

  /// Tells lockstep graphs what it has received from every writer: the whole state each time
  /// (a KEEP_LAST 1 update overwritten before it was resent, or sent before a container's
  /// reader matched, must not leave a writer waiting), when something changed and every
  /// 100 ms.
  void publish_progress() {
    if (!progress_writer) return;
    const auto now = std::chrono::steady_clock::now();
    bool changed = false;
    struct Item {
      std::string topic;
      WriterGid gid;
      ReceiptLedger::Progress p;
    };
    std::vector<Item> items;
    {
      std::lock_guard lock(topics_mutex);
      for (auto& [name, t] : topics) {
        if (!t->reader) continue;
        std::lock_guard ledger_lock(t->ledger_mutex);
        for (const auto& [gid, p] : t->ledger.progress()) {
          std::uint64_t& sent = progress_sent[{t.get(), gid}];
          if (sent != p.received) changed = true;
          sent = p.received;
          items.push_back({t->ros_topic, gid, p});
        }
      }
    }
    if (items.empty() || (!changed && now - progress_sent_at < std::chrono::milliseconds(100)))
      return;
    progress_sent_at = now;
    auto sample = runtime::make_sample<msgs::avs_msgs::WriterCounts>();
    runtime::set_string(sample->header.frame_id, "avs bag record");
    runtime::resize_sequence(sample->writers, static_cast<std::uint32_t>(items.size()));
    for (std::size_t i = 0; i < items.size(); ++i) {
      auto& out = sample->writers._buffer[i];
      std::copy(items[i].gid.begin(), items[i].gid.end(), std::begin(out.writer_gid));
      runtime::set_string(out.topic, items[i].topic);
      out.samples = items[i].p.received;
      out.last_source_timestamp_ns = items[i].p.newest_source_time_ns;
    }
    if (const dds_return_t rc = dds_write(progress_writer.get(), sample.get()); rc < 0) {
      if (!progress_failed) {
        std::fprintf(stderr, "avs bag record: WARNING: writing /avs/recorder_progress: %s\n",
                     dds_strretcode(rc));
      }
      progress_failed = true;  // said once; the recording goes on
    }
  }

  /// Reports received so far, per (topic, writer): to wait for fresh ones when stopping.
  std::map<std::pair<RecordedTopic*, WriterGid>, std::uint64_t> report_counts() const {
    std::map<std::pair<RecordedTopic*, WriterGid>, std::uint64_t> out;
    std::lock_guard lock(topics_mutex);
    for (auto& [name, t] : topics) {
      std::lock_guard ledger_lock(t->ledger_mutex);
      for (const auto& [gid, r] : t->ledger.results())
        if (r.reports > 0) out[{t.get(), gid}] = r.reports;
    }
    return out;
  }

  void take_all() {
    std::vector<RecordedTopic*> readers;
    {
      std::lock_guard lock(topics_mutex);
      for (auto& [name, t] : topics) {
        if (t->reader) readers.push_back(t.get());
      }
    }
    for (RecordedTopic* t : readers) {
      // The log time of each sample is read when it is taken: one clock reading for the
      // whole batch came before samples that arrived while it was taken, and gave 47 of
      // a sim_static recording a publish time after their log time (issue 20 section 6).
      t->reader->take(1024, [&](ddsi_serdata* data, const dds_sample_info_t& info) {
        enqueue(*t, data, info, wall_ns());
      });
    }
  }

  void update_loss() {
    std::lock_guard lock(topics_mutex);
    for (auto& [name, t] : topics) {
      if (!t->reader) continue;
      const dds::ReaderLoss loss = t->reader->loss();
      t->dds_lost = loss.lost;
      t->dds_rejected = loss.rejected;
      t->incompatible = t->reader->incompatible_writers();
    }
  }

  void reader_loop() {
    try {
      std::vector<dds_attach_t> triggered(64);
      auto next_loss_check = std::chrono::steady_clock::now();
      const auto read_once = [&](dds_duration_t wait) {
        waitset->wait(triggered.data(), triggered.size(), wait);
        for (const auto& p : discovery->poll()) add_publication(p);
        take_all();
        take_counts();
        publish_progress();
      };
      while (!stop_reading) {
        read_once(DDS_MSECS(50));
        if (std::chrono::steady_clock::now() >= next_loss_check) {
          update_loss();
          next_loss_check += std::chrono::milliseconds(200);
        }
      }
      // Stopping: the reconciliation ends on counts sent after the stop, so every writer that
      // reports gets up to kFinalReportWait to report again (its last sample may still be on
      // its way after that: a little longer to take it). Samples that come meanwhile are
      // recorded too. Not after a failure: the file is gone.
      if (!finished) {
        const auto before = report_counts();
        const auto deadline = std::chrono::steady_clock::now() + kFinalReportWait;
        while (std::chrono::steady_clock::now() < deadline) {
          read_once(DDS_MSECS(20));
          const auto now_counts = report_counts();
          const bool all_fresh = std::all_of(before.begin(), before.end(), [&](const auto& kv) {
            auto it = now_counts.find(kv.first);
            return it != now_counts.end() && it->second > kv.second;
          });
          if (all_fresh) break;
        }
        const auto grace_end = std::chrono::steady_clock::now() + kFinalSampleGrace;
        while (std::chrono::steady_clock::now() < grace_end) read_once(DDS_MSECS(10));
      }
      // Whatever DDS still holds goes into the file too.
      for (const auto& p : discovery->poll()) add_publication(p);
      take_all();
      take_counts();
      update_loss();
    } catch (const std::exception& e) {
      fail(std::string("reading DDS: ") + e.what());
    }
    std::lock_guard lock(queue_mutex);
    readers_done = true;
    queue_changed.notify_all();
  }

  void check(const mcap::Status& s, const std::string& what) {
    if (!s.ok()) throw Error(what + ": " + s.to_string());
  }

  void open_file() {
    const std::filesystem::path path = split_path(options.output, file_index);
    mcap::WriterOptions wo;
    wo.compression = options.compression;
    wo.compression_level = options.compression_level;
    wo.chunk_size_bytes = options.chunk_size_bytes;
    check(writer.open(path, wo), "open " + path.string());
    channels.clear();
    {
      std::lock_guard lock(topics_mutex);
      for (auto& [name, t] : topics) t->written_to_open_file = 0;
    }
    file_start = 0;
    std::lock_guard lock(error_mutex);
    files.push_back(path);
  }

  mcap::ChannelId channel_for(RecordedTopic& t) {
    auto it = channels.find(&t);
    if (it != channels.end()) return it->second;
    mcap::SchemaId schema = 0;
    check(writer.add_schema(t.ros_type, "ros2msg", t.schema_text, schema),
          "add schema " + t.ros_type);
    std::string qos;
    {
      std::lock_guard lock(topics_mutex);
      qos = offered_qos_yaml(t.offered);
    }
    mcap::ChannelId id = 0;
    check(writer.add_channel(t.ros_topic, "cdr", schema,
                             {{"offered_qos_profiles", qos}, {"topic_type_hash", ""}}, id),
          "add channel " + t.ros_topic);
    channels.emplace(&t, id);
    return id;
  }

  void write_loss_metadata() {
    mcap::KeyValueMap m;
    std::uint64_t total = 0;
    std::lock_guard lock(topics_mutex);
    for (auto& [name, t] : topics) {
      const TopicCounters c = t->counters();
      std::lock_guard ledger_lock(t->ledger_mutex);
      for (const auto& [gid, r] : t->ledger.results()) {
        if (!r.reconciled) continue;
        // The window of each writer, anchored on two messages in this file (their publish
        // times), so the figure can be checked from the file alone.
        m["writer " + t->ros_topic + " " + hex(gid)] =
            "window_start_ns=" + std::to_string(r.window_start_ns) +
            " window_end_ns=" + std::to_string(r.window_end_ns) +
            " expected=" + std::to_string(r.expected) +
            " received=" + std::to_string(r.received_in_window) +
            " missing=" + std::to_string(r.missing);
      }
      total += c.lost();
      m["received " + t->ros_topic] = std::to_string(t->received.load());
      m["lost " + t->ros_topic] = std::to_string(c.missing) + " missing (writers' counts), " +
                                  std::to_string(t->dds_lost.load()) + " dds_lost, " +
                                  std::to_string(t->dds_rejected.load()) + " dds_rejected, " +
                                  std::to_string(t->queue_dropped.load()) + " queue_dropped";
    }
    m["lost_total"] = std::to_string(total);
    check(writer.add_metadata("avs_bag_record", m), "write loss metadata");
  }

  void writer_loop() {
    try {
      auto last_flush = std::chrono::steady_clock::now();
      const auto flush_every = std::chrono::duration<double>(options.flush_interval_s);
      std::vector<QueuedSample> batch;
      for (;;) {
        bool done = false;
        {
          std::unique_lock lock(queue_mutex);
          queue_changed.wait_for(lock, std::chrono::milliseconds(100),
                                 [&] { return !queue.empty() || readers_done; });
          batch.assign(queue.begin(), queue.end());
          queue.clear();
          done = readers_done && batch.empty();
        }
        for (std::size_t i = 0; i < batch.size(); ++i) {
          QueuedSample& s = batch[i];
          if (file_start == 0) file_start = s.log_time;
          if (FileSplit{options.max_size_bytes, options.max_duration_s}.starts_new_file(
                  file_bytes, file_start, s.log_time)) {
            check(writer.close(), "close " + split_path(options.output, file_index).string());
            ++file_index;
            open_file();
            file_start = s.log_time;
            file_bytes = 0;
          }
          const mcap::ChannelId channel = channel_for(*s.topic);
          ddsrt_iovec_t ref;
          ddsi_serdata* held = ddsi_serdata_to_ser_ref(s.data, 0, s.size, &ref);
          const mcap::Status st = writer.write(
              channel, s.log_time, s.publish_time,
              std::span<const std::byte>(static_cast<const std::byte*>(ref.iov_base), ref.iov_len));
          ddsi_serdata_to_ser_unref(held, &ref);
          ddsi_serdata_unref(s.data);
          s.data = nullptr;
          queued_bytes.fetch_sub(s.size, std::memory_order_relaxed);
          if (!st.ok()) {
            s.topic->write_failed.fetch_add(1, std::memory_order_relaxed);
            for (std::size_t j = i + 1; j < batch.size(); ++j) {
              batch[j].topic->write_failed.fetch_add(1, std::memory_order_relaxed);
              queued_bytes.fetch_sub(batch[j].size, std::memory_order_relaxed);
              ddsi_serdata_unref(batch[j].data);
            }
            batch.clear();
            throw Error("write " + s.topic->ros_topic + ": " + st.to_string());
          }
          s.topic->written.fetch_add(1, std::memory_order_relaxed);
          ++s.topic->written_to_open_file;
        }
        batch.clear();
        file_bytes = writer.statistics().file_bytes;
        if (std::chrono::steady_clock::now() - last_flush >= flush_every) {
          check(writer.flush_chunk(), "flush chunk");
          last_flush = std::chrono::steady_clock::now();
        }
        if (done) break;
      }
      write_loss_metadata();
      check(writer.close(), "close " + split_path(options.output, file_index).string());
    } catch (const std::exception& e) {
      fail(e.what());
      // The messages handed to the writer but not in a chunk it wrote (the chunk being filled
      // when the disk filled up, queued chunks) are lost too: "written" is what the file has.
      for (auto& [topic, channel] : channels) {
        const std::uint64_t in_file = writer.messages_in_file(channel);
        const std::uint64_t unwritten =
            topic->written_to_open_file - std::min(topic->written_to_open_file, in_file);
        topic->written.fetch_sub(unwritten);
        topic->write_failed.fetch_add(unwritten);
        topic->written_to_open_file -= unwritten;
      }
      // Release what is still queued, counting it as lost, so nothing vanishes silently.
      std::unique_lock lock(queue_mutex);
      for (;;) {
        for (auto& s : queue) {
          s.topic->write_failed.fetch_add(1);
          queued_bytes.fetch_sub(s.size);
          ddsi_serdata_unref(s.data);
        }
        queue.clear();
        if (readers_done) break;
        queue_changed.wait_for(lock, std::chrono::milliseconds(50));
      }
      if (writer.is_open()) (void)writer.close();
    }
  }
};

Recorder::Recorder(RecordOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  Impl& m = *impl_;
  if (m.options.output.empty()) throw Error("avs bag record: no output file (-o FILE)");
  if (!m.options.all && m.options.topics.empty() && m.options.include_regex.empty()) {
    throw Error("avs bag record: say what to record: -a, topic names, or -e REGEX");
  }
  try {
    if (!m.options.include_regex.empty()) m.include.emplace(m.options.include_regex);
    if (!m.options.exclude_regex.empty()) m.exclude.emplace(m.options.exclude_regex);
  } catch (const std::regex_error& e) {
    throw Error(std::string("avs bag record: bad regular expression: ") + e.what());
  }
  for (const auto& t : m.options.topics) m.wanted.insert(ros_topic_of(t));
  const auto dir = m.options.output.parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir)) {
    throw Error("avs bag record: output directory " + dir.string() + " does not exist");
  }
  m.discovery = std::make_unique<dds::PublicationDiscovery>(m.participant);
  m.waitset = std::make_unique<dds::WaitSet>(m.participant);
  dds::Entity discovery_condition(runtime::check_dds(
      dds_create_readcondition(m.discovery->reader(), DDS_ANY_STATE), "discovery read condition"));
  m.waitset->attach(discovery_condition.get(), 1);
  m.conditions.push_back(std::move(discovery_condition));
  {
    // The topic with default QoS, as the raw readers make theirs (-a records it too: one
    // participant's topics of one name must agree). The reader deep enough for every
    // container's report between two takes (one instance: the type has no key).
    const char* name = "rt/avs/writer_counts";
    m.counts_topic = dds::Entity(runtime::check_dds(
        dds_create_topic(m.participant.get(),
                         msg::TypeSupport<msgs::avs_msgs::WriterCounts>::descriptor(), name,
                         nullptr, nullptr),
        std::string("create topic ") + name));
    runtime::QosProfile profile;
    profile.depth = 256;
    runtime::Qos q(profile);
    m.participant.apply_partition(q.get());
    m.counts_reader = dds::Entity(runtime::check_dds(
        dds_create_reader(m.participant.get(), m.counts_topic.get(), q.get(), nullptr),
        std::string("create reader on ") + name));
    // Its progress: the last value is what counts (KEEP_LAST 1).
    const char* progress_name = "rt/avs/recorder_progress";
    m.progress_topic = dds::Entity(runtime::check_dds(
        dds_create_topic(m.participant.get(),
                         msg::TypeSupport<msgs::avs_msgs::WriterCounts>::descriptor(),
                         progress_name, nullptr, nullptr),
        std::string("create topic ") + progress_name));
    runtime::QosProfile progress_profile;
    progress_profile.depth = 1;
    runtime::Qos pq(progress_profile);
    m.participant.apply_partition(pq.get());
    // Not fatal: a recorder whose DDS permissions do not let it publish still records; only
    // lockstep graphs cannot wait for it.
    const dds_entity_t progress_writer =
        dds_create_writer(m.participant.get(), m.progress_topic.get(), pq.get(), nullptr);
    if (progress_writer > 0) {
      m.progress_writer = dds::Entity(progress_writer);
    } else {
      std::fprintf(stderr,
                   "avs bag record: WARNING: cannot publish %s (%s): lockstep graphs will not "
                   "wait for this recorder and it may lose samples (it counts them)\n",
                   progress_name, dds_strretcode(progress_writer));
    }
    dds::Entity counts_condition(
        runtime::check_dds(dds_create_readcondition(m.counts_reader.get(), DDS_ANY_STATE),
                           "/avs/writer_counts read condition"));
    m.waitset->attach(counts_condition.get(), 1);
    m.conditions.push_back(std::move(counts_condition));
  }
}

Recorder::~Recorder() {
  try {
    stop();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "avs bag record: %s\n", e.what());
  }
}

void Recorder::start() {
  Impl& m = *impl_;
  if (m.started) return;
  m.open_file();
  m.started = true;
  m.writer_thread = std::thread([&m] { m.writer_loop(); });
  m.reader_thread = std::thread([&m] { m.reader_loop(); });
}

void Recorder::stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  m.stop_reading = true;
  m.waitset->wake();
  m.reader_thread.join();
  m.writer_thread.join();
  std::lock_guard lock(m.error_mutex);
  if (!m.error.empty()) throw Error("avs bag record: " + m.error);
}

RecorderStatus Recorder::status() const {
  const Impl& m = *impl_;
  RecorderStatus s;
  {
    std::lock_guard lock(m.topics_mutex);
    for (const auto& [name, t] : m.topics) {
      TopicCounters c = t->counters();
      s.received += c.received;
      s.written += c.written;
      s.bytes_received += c.bytes;
      s.lost += c.lost();
      s.topics.push_back(std::move(c));
    }
  }
  std::sort(s.topics.begin(), s.topics.end(), [](auto& a, auto& b) { return a.topic < b.topic; });
  s.queue_bytes = m.queued_bytes;
  s.queue_bytes_peak = m.queued_peak;
  s.file_bytes = m.file_bytes;
  s.finished = m.finished;
  std::lock_guard lock(m.error_mutex);
  s.error = m.error;
  s.files = m.files;
  return s;
}

std::string format_record_report(const RecorderStatus& s) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line, "%-32s %-36s %10s %10s %10s\n", "topic", "type", "received",
                "written", "lost");
  out << line;
  for (const auto& t : s.topics) {
    if (!t.skipped_because.empty()) {
      out << t.topic << ": NOT recorded: " << t.skipped_because << "\n";
      continue;
    }
    std::snprintf(line, sizeof line, "%-32s %-36s %10llu %10llu %10llu\n", t.topic.c_str(),
                  t.type.c_str(), static_cast<unsigned long long>(t.received),
                  static_cast<unsigned long long>(t.written),
                  static_cast<unsigned long long>(t.lost()));
    out << line;
    if (t.lost() > 0) {
      out << "  LOST on " << t.topic << ": ";
      if (t.writers_reconciled > 0) {
        out << t.missing << " of " << t.expected_in_window
            << " never received (the writers' counts), ";
      }
      out << t.dds_lost << " reported lost by DDS (sample lost), " << t.dds_rejected
          << " rejected by DDS (sample rejected), " << t.queue_dropped
          << " dropped by the recorder (queue full)";
      if (t.write_failed > 0) {
        out << ", " << t.write_failed << " not written (the file failed)";
      }
      out << "\n";
    }
    if (t.incompatible_writers > 0) {
      out << "  NOT MATCHED on " << t.topic << ": " << t.incompatible_writers
          << " writer(s) with QoS incompatible with the recorder's (" << t.qos
          << "): their samples are not recorded\n";
    }
  }
  std::string unreconciled;
  std::size_t reconciled = 0, recorded = 0;
  for (const auto& t : s.topics) {
    if (!t.skipped_because.empty() || t.received == 0) continue;
    ++recorded;
    if (t.writers_reconciled > 0 && t.writers_unreconciled == 0) {
      ++reconciled;
    } else {
      unreconciled += (unreconciled.empty() ? "" : ", ") + t.topic;
    }
  }
  out << "reconciled with the writers' own counts: " << reconciled << " of " << recorded
      << " topic(s)";
  if (!unreconciled.empty()) {
    out << "; not (writers without /avs/writer_counts, or seen too briefly; only what DDS "
           "reports is counted lost there): "
        << unreconciled;
  }
  out << "\n";
  out << "total: " << s.received << " received, " << s.written << " written, " << s.lost
      << " lost; queue peak " << s.queue_bytes_peak / 1e6 << " MB\n";
  for (const auto& f : s.files) out << "file: " << f.string() << "\n";
  if (!s.error.empty()) out << "ERROR: " << s.error << "\n";
  return out.str();
}

}  // namespace avs::bag
