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

#include "avs/bag/qos_yaml.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/mcap/writer.hpp"
#include "avs/msg/type_registry.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/topic_name.hpp"

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

std::filesystem::path split_path(const std::filesystem::path& first, int index) {
  if (index == 0) return first;
  std::filesystem::path p = first;
  const std::string ext = p.has_extension() ? p.extension().string() : std::string(".mcap");
  p.replace_filename(p.stem().string() + "_" + std::to_string(index) + ext);
  return p;
}

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
};

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
        t->reader = std::make_unique<dds::RawReader>(participant, *type, p.topic, q);
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
      while (!stop_reading) {
        waitset->wait(triggered.data(), triggered.size(), DDS_MSECS(50));
        for (const auto& p : discovery->poll()) add_publication(p);
        take_all();
        if (std::chrono::steady_clock::now() >= next_loss_check) {
          update_loss();
          next_loss_check += std::chrono::milliseconds(200);
        }
      }
      // Whatever DDS still holds goes into the file too.
      for (const auto& p : discovery->poll()) add_publication(p);
      take_all();
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
      const std::uint64_t lost = t->dds_lost + t->dds_rejected + t->queue_dropped;
      total += lost;
      m["received " + t->ros_topic] = std::to_string(t->received.load());
      m["lost " + t->ros_topic] = std::to_string(t->dds_lost.load()) + " dds_lost, " +
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
          const bool too_big = options.max_size_bytes > 0 && file_bytes >= options.max_size_bytes;
          const bool too_long =
              options.max_duration_s > 0 &&
              static_cast<double>(s.log_time - std::min(s.log_time, file_start)) * 1e-9 >=
                  options.max_duration_s;
          if (too_big || too_long) {
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
      TopicCounters c;
      c.topic = t->ros_topic;
      c.type = t->ros_type;
      c.qos = t->requested_qos;
      c.publishers = t->writers.size();
      c.received = t->received;
      c.written = t->written;
      c.bytes = t->bytes;
      c.dds_lost = t->dds_lost;
      c.dds_rejected = t->dds_rejected;
      c.queue_dropped = t->queue_dropped;
      c.write_failed = t->write_failed;
      c.incompatible_writers = t->incompatible;
      c.skipped_because = t->skipped_because;
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
      out << "  LOST on " << t.topic << ": " << t.dds_lost
          << " reported lost by DDS (sample lost), " << t.dds_rejected
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
  out << "total: " << s.received << " received, " << s.written << " written, " << s.lost
      << " lost; queue peak " << s.queue_bytes_peak / 1e6 << " MB\n";
  for (const auto& f : s.files) out << "file: " << f.string() << "\n";
  if (!s.error.empty()) out << "ERROR: " << s.error << "\n";
  return out.str();
}

}  // namespace avs::bag
