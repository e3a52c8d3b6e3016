#include "avs/runtime/container.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "avs/runtime/dds.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/realtime.hpp"
#include "avs/runtime/ros_discovery.hpp"
#include "avs/runtime/topic_name.hpp"
#include "diagnostic_msgs.h"
#include "parameter_service.hpp"
#include "recorder_acks.hpp"
#include "rosgraph_msgs.h"
#include "writer_counts.hpp"

namespace avs::runtime {

namespace {

/// A measured figure on /diagnostics: 6 significant digits ("999.971", "1000", "0.0123"), not
/// std::to_string's fixed 6 decimals ("1000.000000").
std::string diagnostic_number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

/// Samples posted to one subscription's lane and those skipped there (overload, see
/// LocalSubscription::keep_last). Shared by the posted callbacks and the component's host.
struct SubscriptionBacklog {
  std::string port;                       ///< the component's port (for /diagnostics)
  std::atomic<std::uint64_t> posted{0};   ///< samples posted to the lane so far
  std::atomic<std::uint64_t> skipped{0};  ///< of those, dropped for newer ones
};

/// One sample callback of one component, already guarded (active check, exceptions).
struct LocalSubscription {
  int lane;
  std::function<void(std::shared_ptr<const void>)> deliver;
  /// KEEP_LAST depth on the lane (issue 16 section 3, skip to the newest input): a sample whose
  /// turn comes when `keep_last` newer ones have been posted behind it is skipped and counted,
  /// as a DDS reader's history of that depth would have overwritten it. 0: every sample is
  /// delivered (lockstep and follower clocks, where time waits for the slowest component, and
  /// open ports such as recorders, which account for every sample themselves).
  std::uint32_t keep_last = 0;
  std::shared_ptr<SubscriptionBacklog> backlog;
};

/// Runs on the lane: hands `sample` to the subscription `context`, unless KEEP_LAST skips it.
void deliver_sample(const void* context, const std::shared_ptr<const void>& sample,
                    std::uint64_t sequence) {
  const auto& sub = *static_cast<const LocalSubscription*>(context);
  if (sub.keep_last > 0 &&
      sub.backlog->posted.load(std::memory_order_relaxed) - sequence >= sub.keep_last) {
    sub.backlog->skipped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  sub.deliver(sample);
}

/// Queues `sample` for `sub` on its lane (the one path of local and DDS-received samples),
/// without an allocation (Scheduler::post with a function pointer). `sub` lives as long as the
/// container and never moves: subscriptions are made before it runs, kept in a deque, never
/// removed.
void post_sample(Scheduler& scheduler, const LocalSubscription& sub,
                 std::shared_ptr<const void> sample) {
  const std::uint64_t sequence =
      sub.keep_last == 0 ? 0 : sub.backlog->posted.fetch_add(1, std::memory_order_relaxed) + 1;
  scheduler.post(sub.lane, &deliver_sample, &sub, std::move(sample), sequence);
}

/// Everything the container knows about one DDS topic.
struct TopicEntry {
  std::string dds_name;
  const msg::TypeEntry* type = nullptr;
  std::unique_ptr<dds::Topic> topic;
  std::unique_ptr<dds::Writer> writer;
  /// What the writer has written, for /avs/writer_counts (recorders reconcile against it).
  WriterTally tally;
  std::uint32_t history_depth = 0;  ///< the writer's KEEP_LAST depth
  bool reliable = true;
  /// The writer keeps its last samples for readers that match later (transient local):
  /// they must reach the DDS writer even when no remote reader is matched yet.
  bool latched = false;
  std::unique_ptr<dds::Reader> reader;
  dds::Entity read_condition;
  /// A deque: queued deliveries point at their subscription (post_sample), and adding one
  /// (before the container runs) must not move the others, even with a delivery already queued.
  std::deque<LocalSubscription> subscriptions;
};

}  // namespace

class ComponentHost;

struct Container::Impl {
  Impl(const graph::Graph& g, const graph::ContainerSpec& s);

  TopicEntry& topic(const std::string& dds_name, const msg::TypeEntry& type, const QosProfile& qos);
  void reader_loop();
  void fail(const std::string& what);
  void publish_diagnostics(dds::Writer& writer);

  const graph::Graph& graph;
  const graph::ContainerSpec& spec;
  Logger log;
  dds::Participant participant;
  std::unique_ptr<Scheduler> scheduler;
  std::map<std::string, std::unique_ptr<TopicEntry>> topics;
  std::vector<std::unique_ptr<ComponentHost>> hosts;
  std::atomic<bool> failed{false};
  std::atomic<bool> running{false};
  std::unique_ptr<dds::WaitSet> waitset;
  std::unique_ptr<dds::Writer> clock_writer;
  std::unique_ptr<dds::Topic> clock_topic;
  std::vector<TopicEntry*> read_topics;  // waitset attach token = index
  TopicEntry* clock_follow = nullptr;
  Time last_diagnostics{};  ///< clock time of the previous /diagnostics report
  std::unique_ptr<ParameterService> parameter_service;
  std::unique_ptr<RosDiscoveryWriter> ros_discovery;
  std::unique_ptr<WriterCountsPublisher> writer_counts;
  std::unique_ptr<RecorderAcks> recorder_acks;
  /// Serialised <-> typed samples, per type, for components with open ports.
  std::map<std::string, std::unique_ptr<dds::CdrCodec>> codecs;
  const dds::CdrCodec& codec(const msg::TypeEntry& type);
  /// The DDS type that the graph's components (in any container) declare for the ROS topic
  /// `ros_name` on a publisher port; empty when none does.
  std::string declared_type(const std::string& ros_name) const;
};

namespace {

TimeMode time_mode_for(const graph::Graph& g, const graph::ContainerSpec& s) {
  if (g.clock.source == graph::ClockSpec::Source::wall) return TimeMode::wall;
  const std::string master =
      g.clock.master.empty() && !g.containers.empty() ? g.containers.front().name : g.clock.master;
  if (s.name != master) return TimeMode::sim_follower;
  return g.clock.mode == graph::ClockSpec::Mode::lockstep ? TimeMode::sim_lockstep
                                                          : TimeMode::sim_realtime;
}

}  // namespace

/// The ComponentContext a component sees: its parameters, ports, timers and clock; and the
/// node its parameter services answer for.
class ComponentHost final : public ComponentContext, public ParameterNode {
 public:
  ComponentHost(Container::Impl& container, const graph::ComponentInstance& instance,
                const RegisteredComponent& registered, int lane)
      : container_(container),
        instance_(instance),
        registered_(registered),
        lane_(lane),
        log_(instance.name),
        node_name_(resolve_topic_name(container.graph.ns, instance.name)),
        values_(instance.parameters) {}

  const std::string& name() const override { return instance_.name; }
  /// Read on the component's thread, the one thread that changes them (apply_later).
  const ParameterValues& parameters() const override { return values_; }

  const std::string& node_name() const override { return node_name_; }
  const ComponentSpec& node_spec() const override { return registered_.spec; }
  ParameterValues snapshot() const override {
    std::lock_guard lock(values_mutex_);
    return values_;
  }
  void apply_later(ParameterValues values, std::vector<std::string> changed,
                   std::function<void(const std::string&)> done) override {
    container_.scheduler->post(lane_, [this, values = std::move(values),
                                       changed = std::move(changed), done = std::move(done)] {
      std::string refusal;
      try {
        if (!component) throw Error("the component is not running");
        component->on_parameters_changed(values, changed);
        std::lock_guard lock(values_mutex_);
        values_ = values;
      } catch (const std::exception& e) {
        refusal = e.what();
      }
      done(refusal);
    });
  }
  const Logger& log() const override { return log_; }
  Time now() const override { return container_.scheduler->now(); }
  bool uses_sim_time() const override { return container_.scheduler->mode() != TimeMode::wall; }
  int dds_domain() const override { return container_.graph.domain_id; }
  const std::string& dds_partition() const override { return container_.graph.partition; }

  TimerId create_timer(Duration period, std::function<void()> callback) override {
    auto ticks = std::make_shared<std::atomic<std::uint64_t>>(0);
    auto counted = [ticks, fn = std::move(callback)] {
      ticks->fetch_add(1, std::memory_order_relaxed);
      fn();
    };
    const TimerId id = container_.scheduler->add_timer(lane_, period, guard(std::move(counted)));
    std::lock_guard lock(timers_mutex_);
    timers_.push_back(id);
    // The first window starts at the first tick.
    timer_rates_.push_back({id, period, container_.scheduler->now() + period, ticks, 0, {}});
    return id;
  }

  void cancel_timer(TimerId id) override {
    container_.scheduler->cancel_timer(id);
    std::lock_guard lock(timers_mutex_);
    std::erase_if(timer_rates_, [id](const TimerRate& t) { return t.id == id; });
  }

  void cancel_all_timers() {
    std::lock_guard lock(timers_mutex_);
    for (TimerId id : timers_) container_.scheduler->cancel_timer(id);
    timers_.clear();
    timer_rates_.clear();
  }

  /// The slowest of this component's timers against its configured rate (diagnostics timer,
  /// once a second): achieved and configured Hz, or nothing before any timer was measured. Each
  /// timer is measured over windows of at least 100 of its periods (so that one tick more or
  /// less is at most 1 %), the first from its first tick; a timer slower than 100 Hz is measured
  /// over several reports.
  struct TimerShortfall {
    double achieved_hz = 0;
    double configured_hz = 0;
    bool below = false;  ///< achieved < 95 % of configured
  };
  std::optional<TimerShortfall> check_timer_rates(Time now) {
    std::lock_guard lock(timers_mutex_);
    std::optional<TimerShortfall> worst;
    for (TimerRate& t : timer_rates_) {
      const double configured_hz = 1e9 / static_cast<double>(t.period.count());
      const double window_s = static_cast<double>((now - t.window_start).count()) * 1e-9;
      if (window_s * configured_hz >= 100.0) {
        const std::uint64_t ticks = t.ticks->load(std::memory_order_relaxed);
        const auto n = static_cast<double>(ticks - t.window_ticks);
        t.last = TimerShortfall{n / window_s, configured_hz, n < 0.95 * window_s * configured_hz};
        t.window_start = now;
        t.window_ticks = ticks;
      }
      if (t.last && (!worst || t.last->achieved_hz / t.last->configured_hz <
                                   worst->achieved_hz / worst->configured_hz)) {
        worst = t.last;
      }
    }
    if (worst && worst->below) {
      // Rate-limited: the first shortfall, then every 10th report that has one.
      if (shortfalls_++ % 10 == 0) {
        log_.warn("timer rate ", worst->achieved_hz, " Hz, below 95 % of its configured ",
                  worst->configured_hz,
                  " Hz (on the container's clock): this machine does not keep the graph's rate "
                  "(warned every 10th second while it lasts)");
      }
    }
    return worst;
  }
  /// The last check_timer_rates result (diagnostics timer only).
  std::optional<TimerShortfall> last_timer_check;
  /// The last skipped_inputs result and rise (diagnostics timer only).
  std::vector<std::pair<std::string, std::string>> last_skips;
  std::uint64_t last_skip_rise = 0;

  void set_active(bool active) { active_ = active; }
  const graph::ComponentInstance& instance() const { return instance_; }
  std::unique_ptr<Component> component;
  /// The topics this component publishes and subscribes to (its node's writers and readers).
  std::vector<const TopicEntry*> published;
  std::vector<const TopicEntry*> subscribed;

 protected:
  std::shared_ptr<PublisherCore> make_publisher(std::string_view port,
                                                const msg::TypeEntry& type) override;
  void make_subscription(std::string_view port, const msg::TypeEntry& type,
                         std::function<void(std::shared_ptr<const void>)> callback) override;

 public:
  std::shared_ptr<SerializedPublisher> serialized_publisher(const std::string& ros_topic,
                                                            const std::string& dds_type,
                                                            const QosProfile& qos) override;
  std::string serialized_subscription(
      const std::string& ros_topic, const std::string& dds_type, const QosProfile& qos,
      std::function<void(std::span<const std::byte>)> callback) override;
  void request_stop(const std::string& why) override {
    log_.info("stopping the container: ", why);
    container_.scheduler->stop();
  }

 private:
  /// publisher/subscription: the writer (reader) and local delivery of one topic.
  TopicEntry& add_publication(const std::string& dds_name, const msg::TypeEntry& type,
                              const QosProfile& qos);
  /// `skip_port`: the declared port whose lane keeps only the newest qos.depth samples under
  /// overload (LocalSubscription::keep_last); empty: every sample is delivered.
  TopicEntry& add_subscription(const std::string& dds_name, const msg::TypeEntry& type,
                               const QosProfile& qos,
                               std::function<void(std::shared_ptr<const void>)> callback,
                               std::string_view skip_port = {});
  /// An open-ports topic: (DDS name after namespace and remaps, its type entry).
  std::pair<std::string, const msg::TypeEntry*> resolve_open(const std::string& ros_topic,
                                                             const std::string& dds_type,
                                                             bool publishing) const;

  /// Runs `fn` now, only while active; an exception fails the container with context.
  template <class F>
  void run_guarded(F&& fn) {
    if (!active_) return;
    const auto start = std::chrono::steady_clock::now();
    try {
      fn();
      record_callback(std::chrono::steady_clock::now() - start);
    } catch (const std::exception& e) {
      container_.fail("component '" + instance_.name + "' (" + instance_.type +
                      "): callback failed: " + e.what());
    }
  }
  /// run_guarded as a callback to keep (timers).
  std::function<void()> guard(std::function<void()> fn) {
    return [this, fn = std::move(fn)] { run_guarded(fn); };
  }

 public:
  /// Callback statistics since the last diagnostics report (wall-clock processing time).
  struct Stats {
    std::uint64_t callbacks = 0;
    double total_ms = 0;
    double max_ms = 0;
  };
  Stats take_stats() {
    std::lock_guard lock(stats_mutex_);
    return std::exchange(stats_, Stats{});
  }
  /// The component's `rejected_samples` at the previous diagnostics report (diagnostics timer).
  std::uint64_t reported_rejections = 0;

  /// Inputs skipped for newer ones (LocalSubscription::keep_last): `skipped_inputs` in all and
  /// `skipped_inputs/<port>` per port that has skipped, for /diagnostics; the total rise since
  /// the previous call in `*rise`. Logged (rate-limited: the first report with a rise, then
  /// every 10th) so an overloaded stage says so. Diagnostics timer only.
  std::vector<std::pair<std::string, std::string>> skipped_inputs(std::uint64_t* rise) {
    std::vector<std::pair<std::string, std::string>> out;
    std::uint64_t total = 0;
    std::string ports;
    for (const auto& b : backlogs_) {
      const std::uint64_t n = b->skipped.load(std::memory_order_relaxed);
      total += n;
      if (n == 0) continue;
      out.emplace_back("skipped_inputs/" + b->port, std::to_string(n));
      ports += (ports.empty() ? "" : ", ") + b->port + " " + std::to_string(n);
    }
    if (backlogs_.empty()) return out;
    out.insert(out.begin(), {"skipped_inputs", std::to_string(total)});
    *rise = total - reported_skips_;
    reported_skips_ = total;
    if (*rise == 0) skip_reports_ = 0;  // the episode is over: the next one warns at once
    if (*rise > 0 && skip_reports_++ % 10 == 0) {
      log_.warn("input faster than this component: skipped ", *rise,
                " sample(s) for newer ones since the last report (in all: ", ports,
                "; each port keeps its QoS depth of the newest; warned every 10th report while it "
                "lasts)");
    }
    return out;
  }

 private:
  void record_callback(std::chrono::steady_clock::duration d) {
    const double ms = std::chrono::duration<double, std::milli>(d).count();
    std::lock_guard lock(stats_mutex_);
    ++stats_.callbacks;
    stats_.total_ms += ms;
    stats_.max_ms = std::max(stats_.max_ms, ms);
  }

  /// Port -> (DDS topic name, QoS), after remaps and the graph's namespace.
  std::pair<std::string, QosProfile> resolve(std::string_view port, const msg::TypeEntry& type,
                                             bool publishing) const {
    const auto& ports = publishing ? registered_.spec.publishes : registered_.spec.subscribes;
    const PortSpec* found = nullptr;
    for (const auto& p : ports) {
      if (p.name == port) found = &p;
    }
    const std::string what = std::string(publishing ? "publisher" : "subscription") + " port '" +
                             std::string(port) + "' of component '" + instance_.name + "'";
    if (found == nullptr) throw Error(what + " is not declared in the spec of " + instance_.type);
    if (found->dds_type != type.dds_name) {
      throw Error(what + " is declared as " + found->dds_type + " but used as " + type.dds_name);
    }
    const auto remap = instance_.remaps.find(found->name);
    const std::string ros_name =
        resolve_topic_name(container_.graph.ns,
                           remap != instance_.remaps.end() ? remap->second : found->default_topic);
    const auto qos = instance_.qos.find(found->name);
    return {to_dds_topic_name(ros_name), qos != instance_.qos.end() ? qos->second : found->qos};
  }

  Container::Impl& container_;
  const graph::ComponentInstance& instance_;
  const RegisteredComponent& registered_;
  const int lane_;
  Logger log_;
  const std::string node_name_;
  mutable std::mutex values_mutex_;  ///< guards writes of values_ and reads off the lane
  ParameterValues values_;
  std::atomic<bool> active_{false};
  struct TimerRate {
    TimerId id;
    Duration period;
    Time window_start;                                  ///< of the current measuring window
    std::shared_ptr<std::atomic<std::uint64_t>> ticks;  ///< callbacks run (while active)
    std::uint64_t window_ticks;                         ///< `ticks` at window_start
    std::optional<TimerShortfall> last;                 ///< the last complete window
  };
  std::mutex timers_mutex_;
  std::vector<TimerId> timers_;
  std::vector<TimerRate> timer_rates_;
  std::uint64_t shortfalls_ = 0;
  std::mutex stats_mutex_;
  Stats stats_;
  std::vector<std::shared_ptr<const SubscriptionBacklog>> backlogs_;  ///< fixed once running
  std::uint64_t reported_skips_ = 0;
  std::uint64_t skip_reports_ = 0;
};

namespace {

class LocalPublisher final : public PublisherCore {
 public:
  LocalPublisher(Scheduler& scheduler, TopicEntry& topic) : scheduler_(scheduler), topic_(topic) {}

  void publish(std::shared_ptr<const void> sample) override { publish(std::move(sample), false); }
  void publish_unchanged(std::shared_ptr<const void> sample) override {
    publish(std::move(sample), true);
  }
  const std::string& topic() const override { return topic_.dds_name; }
  std::size_t reader_count() const override {
    return topic_.subscriptions.size() + topic_.writer->matched_readers();
  }

 private:
  void publish(std::shared_ptr<const void> sample, bool unchanged) {
    for (const auto& sub : topic_.subscriptions) post_sample(scheduler_, sub, sample);
    // Serialise only when a reader in another participant wants it, now or (latched) later;
    // an unchanged copy is not needed later once this publisher's own copy is in the history.
    const bool send =
        (topic_.latched && !(unchanged && sent_)) || topic_.writer->matched_readers() > 0;
    topic_.tally.publish(*topic_.writer, sample.get(), send);
    sent_ = sent_ || send;
  }

  Scheduler& scheduler_;
  TopicEntry& topic_;
  bool sent_ = false;  ///< a sample of this publisher has been written to DDS
};

}  // namespace

TopicEntry& ComponentHost::add_publication(const std::string& dds_name, const msg::TypeEntry& type,
                                           const QosProfile& qos) {
  if (container_.running) throw Error("publishers must be created in the constructor");
  TopicEntry& topic = container_.topic(dds_name, type, qos);
  if (!topic.writer) {
    topic.writer = std::make_unique<dds::Writer>(container_.participant, *topic.topic, qos);
    topic.latched = qos.durability == Durability::transient_local;
    topic.history_depth = qos.depth;
    topic.reliable = qos.reliability == Reliability::reliable;
  }
  published.push_back(&topic);
  return topic;
}

TopicEntry& ComponentHost::add_subscription(
    const std::string& dds_name, const msg::TypeEntry& type, const QosProfile& qos,
    std::function<void(std::shared_ptr<const void>)> callback, std::string_view skip_port) {
  if (container_.running) throw Error("subscriptions must be created in the constructor");
  TopicEntry& topic = container_.topic(dds_name, type, qos);
  if (!topic.reader)
    topic.reader = std::make_unique<dds::Reader>(container_.participant, *topic.topic, qos);
  subscribed.push_back(&topic);
  LocalSubscription sub{lane_,
                        [this, cb = std::move(callback)](std::shared_ptr<const void> sample) {
                          run_guarded([&] { cb(std::move(sample)); });
                        }};
  // Only where the clock does not wait for the component (wall time, or simulated time paced
  // at a real-time factor) can its input outrun it; in lockstep skipping would also make the
  // result depend on thread timing.
  const TimeMode mode = container_.scheduler->mode();
  if (!skip_port.empty() && qos.depth > 0 &&
      (mode == TimeMode::wall || mode == TimeMode::sim_realtime)) {
    sub.keep_last = qos.depth;
    sub.backlog = std::make_shared<SubscriptionBacklog>();
    sub.backlog->port = std::string(skip_port);
    backlogs_.push_back(sub.backlog);
  }
  topic.subscriptions.push_back(std::move(sub));
  return topic;
}

std::shared_ptr<PublisherCore> ComponentHost::make_publisher(std::string_view port,
                                                             const msg::TypeEntry& type) {
  auto [dds_name, qos] = resolve(port, type, true);
  return std::make_shared<LocalPublisher>(*container_.scheduler,
                                          add_publication(dds_name, type, qos));
}

void ComponentHost::make_subscription(std::string_view port, const msg::TypeEntry& type,
                                      std::function<void(std::shared_ptr<const void>)> callback) {
  auto [dds_name, qos] = resolve(port, type, false);
  add_subscription(dds_name, type, qos, std::move(callback), port);
}

std::pair<std::string, const msg::TypeEntry*> ComponentHost::resolve_open(
    const std::string& ros_topic, const std::string& dds_type, bool publishing) const {
  const std::string what = std::string(publishing ? "publisher" : "subscription") + " of '" +
                           ros_topic + "' in component '" + instance_.name + "'";
  if (!registered_.spec.open_ports) {
    throw Error(what + ": " + instance_.type + " declares its ports (no open ports)");
  }
  const auto remap = instance_.remaps.find(ros_topic);
  const std::string ros_name = resolve_topic_name(
      container_.graph.ns, remap != instance_.remaps.end() ? remap->second : ros_topic);
  const std::string type_name = dds_type.empty() ? container_.declared_type(ros_name) : dds_type;
  if (type_name.empty()) {
    throw Error(what + ": no component of the graph publishes " + ros_name +
                ", so its type is unknown (give it, or publish the topic in the graph)");
  }
  const msg::TypeEntry* type = msg::find_type(type_name);
  if (type == nullptr) throw Error(what + ": type " + type_name + " is not known to this build");
  return {to_dds_topic_name(ros_name), type};
}

namespace {

/// Serialised samples in, typed samples to the container's subscribers and to DDS.
class LocalSerializedPublisher final : public SerializedPublisher {
 public:
  LocalSerializedPublisher(Scheduler& scheduler, TopicEntry& topic, const dds::CdrCodec& codec)
      : typed_(scheduler, topic), codec_(codec) {}
  void publish(std::span<const std::byte> cdr) override {
    std::shared_ptr<void> sample;
    try {
      sample = codec_.to_sample(cdr);
    } catch (const std::exception& e) {
      throw Error(typed_.topic() + ": " + e.what());
    }
    typed_.publish(std::move(sample));
  }
  const std::string& topic() const override { return typed_.topic(); }

 private:
  LocalPublisher typed_;
  const dds::CdrCodec& codec_;
};

}  // namespace

std::shared_ptr<SerializedPublisher> ComponentHost::serialized_publisher(
    const std::string& ros_topic, const std::string& dds_type, const QosProfile& qos) {
  auto [dds_name, type] = resolve_open(ros_topic, dds_type, true);
  const dds::CdrCodec& codec = container_.codec(*type);
  return std::make_shared<LocalSerializedPublisher>(*container_.scheduler,
                                                    add_publication(dds_name, *type, qos), codec);
}

std::string ComponentHost::serialized_subscription(
    const std::string& ros_topic, const std::string& dds_type, const QosProfile& qos,
    std::function<void(std::span<const std::byte>)> callback) {
  auto [dds_name, type] = resolve_open(ros_topic, dds_type, false);
  const dds::CdrCodec& codec = container_.codec(*type);
  add_subscription(dds_name, *type, qos,
                   [&codec, cb = std::move(callback)](std::shared_ptr<const void> sample) {
                     const std::vector<std::byte> cdr = codec.to_cdr(sample.get());
                     cb(cdr);
                   });
  return type->dds_name;
}

std::string Container::Impl::declared_type(const std::string& ros_name) const {
  for (const auto& c : graph.containers) {
    for (const auto& instance : c.components) {
      const RegisteredComponent* registered = ComponentRegistry::instance().find(instance.type);
      if (registered == nullptr) continue;
      for (const auto& port : registered->spec.publishes) {
        if (graph::port_topic(graph, instance, port) == ros_name) return port.dds_type;
      }
    }
  }
  return {};
}

const dds::CdrCodec& Container::Impl::codec(const msg::TypeEntry& type) {
  auto& slot = codecs[type.dds_name];
  if (!slot) slot = std::make_unique<dds::CdrCodec>(participant, type);
  return *slot;
}

Container::Impl::Impl(const graph::Graph& g, const graph::ContainerSpec& s)
    : graph(g),
      spec(s),
      log("container/" + s.name),
      participant(g.domain_id, g.partition, kRosParticipantUserData) {
  scheduler = std::make_unique<Scheduler>(time_mode_for(g, s), g.clock.real_time_factor);
}

TopicEntry& Container::Impl::topic(const std::string& dds_name, const msg::TypeEntry& type,
                                   const QosProfile& qos) {
  auto& slot = topics[dds_name];
  if (!slot) {
    slot = std::make_unique<TopicEntry>();
    slot->dds_name = dds_name;
    slot->type = &type;
    slot->topic = std::make_unique<dds::Topic>(participant, type.descriptor, dds_name, qos);
  } else if (slot->type->descriptor != type.descriptor) {
    throw Error("topic " + dds_name + " used with two types: " + slot->type->dds_name + " and " +
                type.dds_name);
  }
  return *slot;
}

void Container::Impl::fail(const std::string& what) {
  log.error(what);
  failed = true;
  scheduler->stop();
}

void Container::Impl::publish_diagnostics(dds::Writer& writer) {
  const Time now = scheduler->now();
  // Timer rates are checked (and a shortfall warned) whether or not anyone reads /diagnostics.
  for (auto& host : hosts) {
    host->last_timer_check = host->check_timer_rates(now);
    host->last_skips = host->skipped_inputs(&host->last_skip_rise);
  }
  if (writer.matched_readers() == 0) return;
  auto array = make_sample<msgs::diagnostic_msgs::DiagnosticArray>();
  const double interval_s = (now - last_diagnostics).count() * 1e-9;
  last_diagnostics = now;
  to_ros_time(now, array->header.stamp);
  resize_sequence(array->status, static_cast<std::uint32_t>(hosts.size()));
  for (std::size_t i = 0; i < hosts.size(); ++i) {
    ComponentHost& host = *hosts[i];
    const auto stats = host.take_stats();
    auto& status = array->status._buffer[i];
    status.level = failed ? 2 : 0;  // DiagnosticStatus ERROR / OK
    set_string(status.name, spec.name + "/" + host.instance().name);
    set_string(status.message, failed ? "container failed" : "active");
    set_string(status.hardware_id, host.instance().type);
    // rate_hz: callbacks (timers and samples) per second of the container's clock since the
    // last report; callback_ms_*: wall-clock time spent in them (the component's latency).
    const double mean_ms =
        stats.callbacks ? stats.total_ms / static_cast<double>(stats.callbacks) : 0.0;
    const std::pair<const char*, std::string> values[] = {
        {"state", failed ? "failed" : (running ? "active" : "inactive")},
        {"callbacks", std::to_string(stats.callbacks)},
        {"rate_hz", diagnostic_number(
                        interval_s > 0 ? static_cast<double>(stats.callbacks) / interval_s : 0.0)},
        {"callback_ms_mean", diagnostic_number(mean_ms)},
        {"callback_ms_max", diagnostic_number(stats.max_ms)}};
    constexpr std::size_t kOwn = std::size(values);
    std::vector<std::pair<std::string, std::string>> extra;
    // The slowest timer against its configured rate (timer-driven components): WARN below 95 %.
    if (const auto& timer = host.last_timer_check) {
      extra.emplace_back("timer_rate_hz", diagnostic_number(timer->achieved_hz));
      extra.emplace_back("timer_configured_hz", diagnostic_number(timer->configured_hz));
      if (timer->below && !failed) {
        status.level = 1;  // DiagnosticStatus WARN
        set_string(status.message, "active, timer below 95 % of its configured rate (" +
                                       diagnostic_number(timer->achieved_hz) + " of " +
                                       diagnostic_number(timer->configured_hz) + " Hz)");
      }
    }
    if (host.component) {
      try {
        for (auto& kv : host.component->diagnostic_values()) extra.push_back(std::move(kv));
      } catch (const std::exception& e) {
        extra.emplace_back("diagnostic_values_error", e.what());
      }
    }
    for (auto& kv : host.last_skips) extra.push_back(kv);
    if (host.last_skip_rise > 0 && !failed) {
      status.level = 1;  // DiagnosticStatus WARN
      set_string(status.message, "active, skipping to the newest input (" +
                                     std::to_string(host.last_skip_rise) +
                                     " since the last report)");
    }
    // Input rejected since the last report (SampleRejections' `rejected_samples`): WARN, so a
    // monitor sees bad inputs without reading the values.
    for (const auto& [key, value] : extra) {
      if (key != "rejected_samples") continue;
      const std::uint64_t rejected = std::strtoull(value.c_str(), nullptr, 10);
      if (!failed && rejected > host.reported_rejections) {
        status.level = 1;  // DiagnosticStatus WARN
        set_string(status.message, "active, rejecting input samples (" +
                                       std::to_string(rejected - host.reported_rejections) +
                                       " since the last report)");
      }
      host.reported_rejections = rejected;
    }
    resize_sequence(status.values, static_cast<std::uint32_t>(kOwn + extra.size()));
    for (std::size_t k = 0; k < kOwn; ++k) {
      set_string(status.values._buffer[k].key, values[k].first);
      set_string(status.values._buffer[k].value, values[k].second);
    }
    for (std::size_t k = 0; k < extra.size(); ++k) {
      set_string(status.values._buffer[kOwn + k].key, extra[k].first);
      set_string(status.values._buffer[kOwn + k].value, extra[k].second);
    }
  }
  writer.write(array.get());
}

void Container::Impl::reader_loop() {
  std::vector<dds_attach_t> triggered(read_topics.size() + 1);
  while (!scheduler->stopped()) {
    int n = 0;
    try {
      n = waitset->wait(triggered.data(), triggered.size(), DDS_MSECS(100));
    } catch (const std::exception& e) {
      fail(std::string("DDS wait failed: ") + e.what());
      return;
    }
    for (int i = 0; i < n; ++i) {
      if (triggered[static_cast<std::size_t>(i)] == 0) continue;  // the guard condition
      TopicEntry& topic =
          *read_topics[static_cast<std::size_t>(triggered[static_cast<std::size_t>(i)] - 1)];
      for (;;) {
        std::shared_ptr<void> sample = make_sample(topic.type->descriptor, topic.type->sample_size);
        void* buffers[1] = {sample.get()};
        dds_sample_info_t info;
        const dds_return_t taken = dds_take(topic.reader->get(), buffers, &info, 1, 1);
        if (taken <= 0) break;
        if (!info.valid_data) continue;
        if (&topic == clock_follow) {
          const auto* clock = static_cast<const rosgraph_msgs_msg_dds__Clock_*>(sample.get());
          scheduler->set_sim_time(from_ros_time(clock->clock));
        }
        for (const auto& sub : topic.subscriptions) post_sample(*scheduler, sub, sample);
      }
    }
  }
}

Container::Container(const graph::Graph& graph, const graph::ContainerSpec& spec)
    : graph_(graph), spec_(spec), impl_(std::make_unique<Impl>(graph, spec)) {}

Container::~Container() = default;

void Container::stop() {
  impl_->scheduler->stop();
}

Time Container::now() const {
  return impl_->scheduler->now();
}

Component* Container::find_component(const std::string& name) const {
  for (const auto& host : impl_->hosts) {
    if (host->instance().name == name) return host->component.get();
  }
  return nullptr;
}

int Container::run() {
  Impl& c = *impl_;
  Scheduler& scheduler = *c.scheduler;
  const bool per_component = spec_.executor == graph::ExecutorKind::thread_per_component;
  const int lane_count = per_component ? static_cast<int>(spec_.components.size()) : 1;
  for (int i = 0; i < std::max(lane_count, 1); ++i) scheduler.add_lane();

  // Configure: construct every component (parameters read, ports made).
  int index = 0;
  for (const auto& instance : spec_.components) {
    const RegisteredComponent* registered = ComponentRegistry::instance().find(instance.type);
    if (registered == nullptr) {
      c.log.error("component '", instance.name, "': unknown type '", instance.type, "'");
      return 1;
    }
    auto host =
        std::make_unique<ComponentHost>(c, instance, *registered, per_component ? index : 0);
    try {
      host->component = registered->factory(*host);
    } catch (const std::exception& e) {
      c.log.error("component '", instance.name, "' (", instance.type,
                  ") failed to load: ", e.what());
      return 1;
    }
    c.hosts.push_back(std::move(host));
    ++index;
  }

  // Clock: the master publishes /clock, followers listen to it.
  const TimeMode mode = scheduler.mode();
  const msg::TypeEntry* clock_type = msg::find_type("rosgraph_msgs::msg::dds_::Clock_");
  const QosProfile clock_qos = *QosProfile::named("clock");
  if (mode == TimeMode::sim_lockstep || mode == TimeMode::sim_realtime) {
    c.clock_topic =
        std::make_unique<dds::Topic>(c.participant, clock_type->descriptor, "rt/clock", clock_qos);
    c.clock_writer = std::make_unique<dds::Writer>(c.participant, *c.clock_topic, clock_qos);
    scheduler.on_time_advanced([&c](Time t) {
      rosgraph_msgs_msg_dds__Clock_ sample{};
      to_ros_time(t, sample.clock);
      if (c.clock_writer->matched_readers() > 0) c.clock_writer->write(&sample);
    });
  } else if (mode == TimeMode::sim_follower) {
    TopicEntry& topic = c.topic("rt/clock", *clock_type, clock_qos);
    if (!topic.reader)
      topic.reader = std::make_unique<dds::Reader>(c.participant, *topic.topic, clock_qos);
    c.clock_follow = &topic;
  }

  // Health: one DiagnosticStatus per component on /diagnostics, every second of the clock.
  {
    const msg::TypeEntry* diag_type =
        msg::find_type("diagnostic_msgs::msg::dds_::DiagnosticArray_");
    TopicEntry& topic = c.topic("rt/diagnostics", *diag_type, QosProfile{});
    if (!topic.writer)
      topic.writer = std::make_unique<dds::Writer>(c.participant, *topic.topic, QosProfile{});
    c.last_diagnostics = scheduler.now();
    scheduler.add_timer(0, std::chrono::seconds(1),
                        [&c, &topic] { c.publish_diagnostics(*topic.writer); });
  }

  // Counts of what the components' writers wrote, for recorders in other processes to
  // reconcile their receipts against (issue 20 section 6, docs/bag.md "Loss accounting").
  {
    std::vector<const TopicEntry*> published;  // each writer once (components may share one)
    for (auto& host : c.hosts) {
      for (const TopicEntry* t : host->published)
        if (std::find(published.begin(), published.end(), t) == published.end())
          published.push_back(t);
    }
    std::vector<WriterCountsPublisher::Entry> entries;
    std::vector<RecorderAcks::Watched> watched;
    for (const TopicEntry* t : published) {
      entries.push_back({t->writer.get(), from_dds_topic_name(t->dds_name), &t->tally});
      watched.push_back({t->writer.get(), &t->tally, t->history_depth, t->reliable});
    }
    c.writer_counts =
        std::make_unique<WriterCountsPublisher>(c.participant, spec_.name, std::move(entries));
    scheduler.add_timer(0, std::chrono::milliseconds(100), [&c, &scheduler] {
      try {
        c.writer_counts->publish(scheduler.now());
      } catch (const std::exception& e) {
        c.log.warn("/avs/writer_counts not published: ", e.what());
      }
    });
    // Lockstep time is the graph's own: it waits for recorders rather than outrun them.
    if (mode == TimeMode::sim_lockstep && graph_.clock.wait_for_recorders) {
      c.recorder_acks = std::make_unique<RecorderAcks>(c.participant, std::move(watched), c.log,
                                                       std::chrono::seconds(2));
      const double start_timeout_s = graph_.clock.recorder_start_timeout_s;
      scheduler.before_time_advance([&c, &scheduler, start_timeout_s,
                                     first = start_timeout_s > 0.0]() mutable {
        try {
          if (first) {  // once: a recorder started first, still being discovered
            first = false;
            const auto started = std::chrono::steady_clock::now();
            const bool found = c.recorder_acks->wait_for_a_recorder(
                std::chrono::duration_cast<Duration>(
                    std::chrono::duration<double>(start_timeout_s)),
                [&scheduler] { return scheduler.stopped(); });
            const double waited_s =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
            if (found) {
              c.log.info("a recorder matched after ", waited_s, " s: starting (clock ",
                         "recorder_start_timeout_s)");
            } else {
              c.log.warn("no recorder matched within ", start_timeout_s,
                         " s (clock recorder_start_timeout_s): starting without one");
            }
          }
          c.recorder_acks->wait([&scheduler] { return scheduler.stopped(); });
        } catch (const std::exception& e) {
          c.log.warn("waiting for recorders: ", e.what());
        }
      });
    }
  }

  // DDS inputs from other processes.
  c.waitset = std::make_unique<dds::WaitSet>(c.participant);
  for (auto& [name, topic] : c.topics) {
    if (!topic->reader) continue;
    c.read_topics.push_back(topic.get());
    topic->read_condition =
        dds::Entity(check_dds(dds_create_readcondition(topic->reader->get(), DDS_ANY_STATE),
                              "read condition on " + name));
    c.waitset->attach(topic->read_condition.get(), static_cast<dds_attach_t>(c.read_topics.size()));
  }

  // Parameters at run time: each component is a node with ROS 2's parameter services.
  {
    std::vector<ParameterNode*> nodes;
    for (auto& host : c.hosts) nodes.push_back(host.get());
    c.parameter_service = std::make_unique<ParameterService>(
        c.participant, std::move(nodes), [&scheduler] { return scheduler.now(); });
    c.parameter_service->start();
  }

  // ROS 2 nodes: each component, with its readers and writers, on ros_discovery_info.
  {
    std::vector<NodeEntities> nodes;
    for (const auto& host : c.hosts) {
      NodeEntities node{graph_.ns.empty() ? "/" : graph_.ns, host->instance().name, {}, {}};
      for (const TopicEntry* t : host->subscribed) node.readers.push_back(gid_of(t->reader->get()));
      for (const TopicEntry* t : host->published) node.writers.push_back(gid_of(t->writer->get()));
      for (dds_entity_t e : c.parameter_service->readers_of(*host))
        node.readers.push_back(gid_of(e));
      for (dds_entity_t e : c.parameter_service->writers_of(*host))
        node.writers.push_back(gid_of(e));
      nodes.push_back(std::move(node));
    }
    c.ros_discovery = std::make_unique<RosDiscoveryWriter>(c.participant);
    c.ros_discovery->publish(nodes);
  }

  // Real-time settings (issue 16 section 3) for every thread there is now (the components'
  // own included) and, inherited, the lanes and the DDS reader started below; undone when
  // run() returns. A refused setting is a warning: the container runs without it.
  const RealtimeScope realtime(spec_.realtime);
  if (!realtime.applied().empty()) c.log.info("real-time settings: ", realtime.applied());
  for (const std::string& line : realtime.refused()) c.log.warn(line);

  // Activate.
  c.running = true;
  for (auto& host : c.hosts) {
    try {
      host->set_active(true);
      host->component->on_activate();
    } catch (const std::exception& e) {
      c.fail("component '" + host->instance().name + "' failed to activate: " + e.what());
      break;
    }
  }
  if (graph_.clock.duration_s && *graph_.clock.duration_s > 0) {
    const Time start = mode == TimeMode::wall ? scheduler.now() : Time{0};
    scheduler.stop_at(start + Duration(static_cast<std::int64_t>(*graph_.clock.duration_s * 1e9)));
  }
  c.log.info("running ", c.hosts.size(), " component(s) on ", lane_count, " thread(s), ",
             mode == TimeMode::wall ? "wall time" : "sim time");

  {
    std::thread reader([&c] { c.reader_loop(); });
    std::vector<std::thread> lanes;
    for (int i = 0; i < lane_count; ++i)
      lanes.emplace_back([&scheduler, i] { scheduler.run_lane(i); });
    for (auto& t : lanes) t.join();
    scheduler.stop();
    c.waitset->wake();
    reader.join();
    c.parameter_service->stop();
  }

  // Deactivate and shut down in reverse order; DDS entities go with the participant.
  for (auto it = c.hosts.rbegin(); it != c.hosts.rend(); ++it) {
    auto& host = **it;
    host.set_active(false);
    host.cancel_all_timers();
    try {
      host.component->on_deactivate();
      host.component->on_shutdown();
    } catch (const std::exception& e) {
      c.log.error("component '", host.instance().name, "' failed to shut down: ", e.what());
      c.failed = true;
    }
  }
  // The final counts: a recorder still running ends its reconciliation with them.
  try {
    c.writer_counts->publish(scheduler.now());
  } catch (const std::exception& e) {
    c.log.warn("final /avs/writer_counts not published: ", e.what());
  }
  c.log.info(c.failed ? "stopped after a failure" : "stopped");
  return c.failed ? 1 : 0;
}

}  // namespace avs::runtime
