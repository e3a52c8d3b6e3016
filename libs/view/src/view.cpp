// The DDS side of `avs view`: discovery of publications (appearing and disappearing), raw
// readers for subscribed channels, /diagnostics with the server's counters. One thread.
#include "avs/view/view.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "avs/introspection/type_database.hpp"
#include "avs/msg/type_registry.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/runtime/time.hpp"
#include "avs/runtime/topic_name.hpp"

namespace avs::view {

namespace {

namespace dds = runtime::dds;

std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

constexpr dds_attach_t kDiscoveryToken = 1;

/// A DDS topic with at least one publisher, and its channel.
struct TopicState {
  std::string dds_topic;
  std::string dds_type;
  Channel channel;  ///< id 0: not advertised (type unknown)
  std::map<dds_instance_handle_t, dds::EndpointQos> writers;
  std::unique_ptr<dds::RawReader> reader;
  dds::Entity condition;
};

}  // namespace

std::filesystem::path built_page_dir() {
#ifdef AVS_VIEW_PAGE_DIR
  return AVS_VIEW_PAGE_DIR;
#else
  return {};
#endif
}

bool is_image_type(const std::string& ros_type) {
  return ros_type == "sensor_msgs/msg/Image" || ros_type == "sensor_msgs/msg/CompressedImage" ||
         ros_type == "sensor_msgs/msg/PointCloud2" || ros_type == "avs_msgs/msg/PatternFrame";
}

struct View::Impl {
  ViewOptions options;
  dds::Participant participant;       ///< discovery and readers
  dds::Participant diag_participant;  ///< /diagnostics, so that our own readers see it too
  std::unique_ptr<Server> server;
  dds::Entity discovery;
  dds::Entity discovery_condition;
  std::unique_ptr<dds::WaitSet> waitset;
  std::array<std::uint8_t, 16> own_guid{};
  std::unique_ptr<dds::Topic> diag_topic;
  std::unique_ptr<dds::Writer> diag_writer;

  // DDS thread only.
  std::map<std::string, TopicState> topics;                   ///< by DDS topic name
  std::map<dds_instance_handle_t, std::string> writer_topic;  ///< writer instance -> topic
  std::map<std::pair<std::string, std::string>, ChannelId> channel_ids;  ///< (topic, type)
  ChannelId next_channel = 1;
  std::set<std::string> warned_types;
  std::uint64_t dropped_reported = 0;

  // Network thread -> DDS thread.
  std::mutex wanted_mutex;
  std::map<ChannelId, bool> wanted_changes;
  std::set<ChannelId> wanted;  ///< DDS thread's view of channels with subscribers

  std::atomic<bool> stop_requested{false};
  std::thread thread;

  explicit Impl(ViewOptions o)
      : options(std::move(o)),
        participant(options.domain, options.partition),
        diag_participant(options.domain, options.partition) {
    server = std::make_unique<Server>(options.server, [this](ChannelId id, bool subscribed) {
      {
        std::lock_guard lock(wanted_mutex);
        wanted_changes[id] = subscribed;
      }
      waitset->wake();
    });
    discovery = dds::Entity(runtime::check_dds(
        dds_create_reader(participant.get(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr),
        "read DCPSPublication"));
    discovery_condition = dds::Entity(runtime::check_dds(
        dds_create_readcondition(discovery.get(), DDS_ANY_STATE), "DCPSPublication condition"));
    waitset = std::make_unique<dds::WaitSet>(participant);
    waitset->attach(discovery_condition.get(), kDiscoveryToken);
    dds_guid_t guid{};
    runtime::check_dds(dds_get_guid(participant.get(), &guid), "participant guid");
    std::copy(std::begin(guid.v), std::end(guid.v), own_guid.begin());
    if (options.diagnostics_period_s > 0) {
      const msg::TypeEntry* type = msg::find_type("diagnostic_msgs::msg::dds_::DiagnosticArray_");
      diag_topic = std::make_unique<dds::Topic>(diag_participant, type->descriptor,
                                                "rt/diagnostics", runtime::QosProfile{});
      diag_writer =
          std::make_unique<dds::Writer>(diag_participant, *diag_topic, runtime::QosProfile{});
    }
  }

  void add_writer(dds_instance_handle_t handle, const dds_builtintopic_endpoint_t& ep) {
    const std::string name = ep.topic_name;
    if (name.rfind("DCPS", 0) == 0) return;
    if (std::equal(own_guid.begin(), own_guid.end(), std::begin(ep.participant_key.v))) return;
    TopicState& t = topics[name];
    const bool is_new = t.writers.empty();
    t.writers[handle] = dds::EndpointQos::from_dds(ep.qos);
    writer_topic[handle] = name;
    if (!is_new) return;
    t.dds_topic = name;
    t.dds_type = ep.type_name;
    if (msg::find_type(t.dds_type) == nullptr) {
      if (warned_types.insert(t.dds_type).second) {
        std::fprintf(stderr, "avs view: NOT advertising %s: type %s is not known to this build\n",
                     name.c_str(), t.dds_type.c_str());
      }
      return;
    }
    Channel& c = t.channel;
    c.topic = name.rfind("rt/", 0) == 0 ? runtime::from_dds_topic_name(name) : name;
    c.schema_name = introspection::ros_type_name(t.dds_type);
    c.schema = introspection::ros2msg_definition(introspection::built_in_types(), t.dds_type);
    c.is_image = is_image_type(c.schema_name);
    // The same topic and type keep their id when they come back (allowed by the protocol).
    auto [it, inserted] = channel_ids.try_emplace({name, t.dds_type}, next_channel);
    if (inserted) ++next_channel;
    c.id = it->second;
    server->advertise(c);
  }

  void remove_writer(dds_instance_handle_t handle) {
    const auto w = writer_topic.find(handle);
    if (w == writer_topic.end()) return;
    const auto t = topics.find(w->second);
    writer_topic.erase(w);
    if (t == topics.end()) return;
    t->second.writers.erase(handle);
    if (!t->second.writers.empty()) return;
    if (t->second.channel.id != 0) {
      server->unadvertise(t->second.channel.id);
      wanted.erase(t->second.channel.id);
    }
    close_reader(t->second);
    topics.erase(t);
  }

  void poll_discovery() {
    for (;;) {
      constexpr int kBatch = 64;
      void* samples[kBatch] = {};
      dds_sample_info_t infos[kBatch];
      const int n = runtime::check_dds(dds_take(discovery.get(), samples, infos, kBatch, kBatch),
                                       "take DCPSPublication");
      for (int i = 0; i < n; ++i) {
        if (infos[i].instance_state != DDS_IST_ALIVE) {
          remove_writer(infos[i].instance_handle);
        } else if (infos[i].valid_data) {
          add_writer(infos[i].instance_handle,
                     *static_cast<const dds_builtintopic_endpoint_t*>(samples[i]));
        }
      }
      if (n > 0) dds_return_loan(discovery.get(), samples, n);
      if (n < kBatch) break;
    }
  }

  TopicState* topic_of(ChannelId id) {
    for (auto& [name, t] : topics) {
      if (t.channel.id == id) return &t;
    }
    return nullptr;
  }

  void open_reader(TopicState& t) {
    if (t.reader) return;
    const msg::TypeEntry* type = msg::find_type(t.dds_type);
    // Best effort and shallow, so that the graph's writers never wait for us; reliable and
    // transient local only when every writer offers it (a latched camera_info, /tf_static).
    dds::EndpointQos q;
    q.reliable = false;
    q.transient_local = true;
    for (const auto& [h, w] : t.writers) q.transient_local = q.transient_local && w.transient_local;
    if (q.transient_local) {
      q.reliable = true;
      for (const auto& [h, w] : t.writers) q.reliable = q.reliable && w.reliable;
      q.transient_local = q.reliable;
    }
    q.depth = 8;
    try {
      t.reader = std::make_unique<dds::RawReader>(participant, *type, t.dds_topic, q);
      t.condition = dds::Entity(runtime::check_dds(
          dds_create_readcondition(t.reader->get(), DDS_ANY_STATE), "condition"));
      waitset->attach(t.condition.get(), static_cast<dds_attach_t>(t.channel.id + 16));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "avs view: cannot read %s: %s\n", t.dds_topic.c_str(), e.what());
      t.reader.reset();
    }
  }

  void close_reader(TopicState& t) {
    if (t.condition) waitset->detach(t.condition.get());
    t.condition.reset();
    t.reader.reset();
  }

  void apply_wanted() {
    std::map<ChannelId, bool> changes;
    {
      std::lock_guard lock(wanted_mutex);
      changes.swap(wanted_changes);
    }
    for (const auto& [id, on] : changes) {
      TopicState* t = topic_of(id);
      if (on) {
        wanted.insert(id);
        if (t != nullptr) open_reader(*t);
      } else {
        wanted.erase(id);
        if (t != nullptr) close_reader(*t);
      }
    }
  }

  void take_samples() {
    for (auto& [name, t] : topics) {
      if (!t.reader) continue;
      const ChannelId id = t.channel.id;
      t.reader->take(256, [&](ddsi_serdata* data, const dds_sample_info_t&) {
        const std::uint64_t now = wall_ns();
        const std::size_t size = ddsi_serdata_size(data);
        auto bytes = std::make_shared<std::vector<std::uint8_t>>(size);
        ddsi_serdata_to_ser(data, 0, size, bytes->data());
        ddsi_serdata_unref(data);
        server->publish(id, now, std::move(bytes));
      });
    }
  }

  void publish_diagnostics() {
    const ServerStats s = server->stats();
    if (!s.valid || !diag_writer) return;
    std::vector<std::pair<std::string, std::string>> values;
    std::uint64_t dropped = 0;
    std::map<ChannelId, std::string> topic_of_channel;
    for (const Channel& c : s.channels) topic_of_channel[c.id] = c.topic;
    values.emplace_back("channels", std::to_string(s.channels.size()));
    values.emplace_back("clients", std::to_string(s.clients.size()));
    values.emplace_back("clients_total", std::to_string(s.clients_total));
    values.emplace_back("rejected_requests", std::to_string(s.rejected_total));
    values.emplace_back("overload_dropped", std::to_string(s.overload_dropped));
    for (const ClientStats& c : s.clients) {
      const std::string p = "client " + std::to_string(c.id) + " ";
      dropped += c.dropped;
      values.emplace_back(p + "remote", c.remote);
      values.emplace_back(p + "max_rate_hz", std::to_string(c.max_rate_hz));
      values.emplace_back(p + "sent", std::to_string(c.sent));
      values.emplace_back(p + "dropped", std::to_string(c.dropped));
      values.emplace_back(p + "rejected", std::to_string(c.rejected));
      for (const SubscriptionCounters& sub : c.subscriptions) {
        const std::string q = p + topic_of_channel[sub.channel] + " ";
        values.emplace_back(q + "sent", std::to_string(sub.sent));
        values.emplace_back(q + "dropped", std::to_string(sub.dropped));
        values.emplace_back(q + "throttled", std::to_string(sub.throttled));
        values.emplace_back(q + "queued", std::to_string(sub.queued));
      }
    }
    auto array = runtime::make_sample<msgs::diagnostic_msgs::DiagnosticArray>();
    runtime::to_ros_time(runtime::Time{static_cast<std::int64_t>(wall_ns())}, array->header.stamp);
    runtime::resize_sequence(array->status, 1);
    auto& status = array->status._buffer[0];
    const bool dropping = dropped > dropped_reported;
    dropped_reported = dropped;
    status.level = dropping || s.overload_dropped > 0 ? 1 : 0;  // WARN / OK
    runtime::set_string(status.name, "view");
    runtime::set_string(status.message,
                        dropping ? "dropping messages for slow clients"
                                 : "serving " + std::to_string(s.clients.size()) + " clients");
    runtime::set_string(status.hardware_id, "avs view :" + std::to_string(server->port()));
    runtime::resize_sequence(status.values, static_cast<std::uint32_t>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) {
      runtime::set_string(status.values._buffer[i].key, values[i].first);
      runtime::set_string(status.values._buffer[i].value, values[i].second);
    }
    diag_writer->write(array.get());
  }

  void loop() {
    try {
      std::vector<dds_attach_t> triggered(64);
      const auto period = std::chrono::duration<double>(options.diagnostics_period_s);
      auto next_diagnostics = std::chrono::steady_clock::now() + period;
      while (!stop_requested) {
        waitset->wait(triggered.data(), triggered.size(), DDS_MSECS(50));
        poll_discovery();
        apply_wanted();
        take_samples();
        if (options.diagnostics_period_s > 0 &&
            std::chrono::steady_clock::now() >= next_diagnostics) {
          publish_diagnostics();
          next_diagnostics +=
              std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
        }
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "avs view: DDS thread stopped: %s\n", e.what());
    }
  }
};

View::View(ViewOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}

View::~View() {
  stop();
}

void View::start() {
  impl_->server->start();
  impl_->thread = std::thread([this] { impl_->loop(); });
}

void View::stop() {
  if (!impl_->thread.joinable()) return;
  impl_->stop_requested = true;
  impl_->waitset->wake();
  impl_->thread.join();
  impl_->server->stop();
}

std::uint16_t View::port() const {
  return impl_->server->port();
}

ServerStats View::stats() const {
  return impl_->server->stats();
}

}  // namespace avs::view
