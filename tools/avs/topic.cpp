// avs topic list | echo | hz | bw: inspect a running graph from any process, through DDS
// discovery (built-in topics) and raw CDR samples of any type this build knows.
#include <dds/ddsi/ddsi_serdata.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <iostream>
#include <map>
#include <set>
#include <thread>

#include "avs/introspection/cdr_reader.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/msg/type_registry.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/parameters.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/ros_discovery.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"

namespace avs::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct EndpointInfo {
  std::string type_name;
  std::string qos;
  runtime::Gid gid{};  ///< the endpoint's GUID (ros_discovery_info names its node by it)
};

struct TopicInfo {
  std::string type_name;
  std::vector<EndpointInfo> publishers;
  std::vector<EndpointInfo> subscribers;
};

std::string describe_qos(const dds_qos_t* qos) {
  std::string s;
  dds_reliability_kind_t reliability;
  dds_duration_t blocking;
  if (dds_qget_reliability(qos, &reliability, &blocking)) {
    s += reliability == DDS_RELIABILITY_RELIABLE ? "reliable" : "best_effort";
  }
  dds_durability_kind_t durability;
  if (dds_qget_durability(qos, &durability)) {
    s += durability == DDS_DURABILITY_VOLATILE ? ", volatile" : ", transient_local";
  }
  dds_history_kind_t history;
  int32_t depth = 0;
  if (dds_qget_history(qos, &history, &depth)) {
    s += history == DDS_HISTORY_KEEP_LAST ? ", keep_last " + std::to_string(depth) : ", keep_all";
  }
  dds_duration_t deadline;
  if (dds_qget_deadline(qos, &deadline) && deadline != DDS_INFINITY) {
    s += ", deadline " + std::to_string(deadline / 1000) + " us";
  }
  return s;
}

/// Sleeps `wait`, in slices, until it is over or an interrupt came; throws on the interrupt.
void sleep_unless_interrupted(std::chrono::milliseconds wait) {
  const auto end = Clock::now() + wait;
  while (Clock::now() < end) {
    if (stop_requested()) throw runtime::Error("interrupted");
    std::this_thread::sleep_for(
        std::min<Clock::duration>(std::chrono::milliseconds(50), end - Clock::now()));
  }
}

/// Reads DDS discovery for `wait`: every other participant's endpoints, by topic.
std::map<std::string, TopicInfo> discover(const runtime::dds::Participant& participant,
                                          std::chrono::milliseconds wait) {
  runtime::dds::EndpointDiscovery discovery(participant);
  sleep_unless_interrupted(wait);
  discovery.update();
  std::map<std::string, TopicInfo> topics;
  for (const auto& [key, e] : discovery.endpoints()) {
    TopicInfo& info = topics[e.topic];
    info.type_name = e.type_name;
    (e.is_writer ? info.publishers : info.subscribers)
        .push_back({e.type_name, describe_qos(e.qos.get()), e.key});
  }
  return topics;
}

/// Accepts "rt/depth", "/depth" or "depth".
std::string dds_topic_of(const std::string& name) {
  if (name.rfind("rt/", 0) == 0) return name;
  return runtime::to_dds_topic_name(runtime::resolve_topic_name("/", name));
}

/// A reader of raw CDR on a topic of any known type, found through discovery.
class RawReader {
 public:
  RawReader(const runtime::dds::Participant& participant, const std::string& topic_arg,
            double wait_s)
      : dds_name_(dds_topic_of(topic_arg)) {
    const auto deadline = Clock::now() + std::chrono::duration<double>(wait_s);
    std::map<std::string, TopicInfo> topics;
    while (true) {
      topics = discover(participant, std::chrono::milliseconds(300));
      auto it = topics.find(dds_name_);
      if (it != topics.end() && !it->second.publishers.empty()) break;
      if (Clock::now() > deadline) {
        throw runtime::Error("no publisher of " + runtime::from_dds_topic_name(dds_name_) +
                             " found within " + runtime::format_number(wait_s) +
                             " s (see `avs topic list`)");
      }
    }
    const TopicInfo& info = topics.at(dds_name_);
    type_ = msg::find_type(info.type_name);
    if (type_ == nullptr) {
      throw runtime::Error(runtime::from_dds_topic_name(dds_name_) + " has type " +
                           runtime::to_ros_type_name(info.type_name) +
                           ", which this build does not know");
    }
    // Match what the publishers offer: reliable only if they all are.
    runtime::QosProfile qos;
    qos.depth = 256;
    for (const auto& p : info.publishers) {
      if (p.qos.rfind("best_effort", 0) == 0) qos.reliability = runtime::Reliability::best_effort;
    }
    topic_ = std::make_unique<runtime::dds::Topic>(participant, type_->descriptor, dds_name_, qos);
    runtime::Qos reader_qos(qos);
    participant.apply_partition(reader_qos.get());
    reader_ = runtime::dds::Entity(runtime::check_dds(
        dds_create_reader(participant.get(), topic_->get(), reader_qos.get(), nullptr),
        "create reader on " + dds_name_));
    waitset_ =
        runtime::dds::Entity(runtime::check_dds(dds_create_waitset(participant.get()), "waitset"));
    condition_ = runtime::dds::Entity(runtime::check_dds(
        dds_create_readcondition(reader_.get(), DDS_ANY_STATE), "read condition"));
    runtime::check_dds(dds_waitset_attach(waitset_.get(), condition_.get(), 0), "attach");
  }

  /// Waits up to `timeout` and calls `fn(bytes, info)` for each sample taken.
  template <class Fn>
  void take(std::chrono::milliseconds timeout, Fn&& fn) {
    dds_waitset_wait(waitset_.get(), nullptr, 0, DDS_MSECS(timeout.count()));
    for (;;) {
      ddsi_serdata* data = nullptr;
      dds_sample_info_t info;
      if (dds_takecdr(reader_.get(), &data, 1, &info, DDS_ANY_STATE) <= 0) break;
      if (info.valid_data) {
        const std::size_t size = ddsi_serdata_size(data);
        buffer_.resize(size);
        ddsi_serdata_to_ser(data, 0, size, buffer_.data());
        fn(std::span<const std::uint8_t>(buffer_), info);
      }
      ddsi_serdata_unref(data);
    }
  }

  const msg::TypeEntry& type() const { return *type_; }
  const std::string& dds_name() const { return dds_name_; }

 private:
  std::string dds_name_;
  const msg::TypeEntry* type_ = nullptr;
  std::unique_ptr<runtime::dds::Topic> topic_;
  runtime::dds::Entity reader_, waitset_, condition_;
  std::vector<std::uint8_t> buffer_;
};

struct CommonOptions {
  std::string topic;
  int domain = 0;  // add_domain_option
  double wait_s = 5.0;
  double duration_s = 0;  // 0 = until Ctrl-C
  long count = 0;         // 0 = unlimited
};

void add_common(Command* cmd, CommonOptions& o, bool needs_topic) {
  if (needs_topic) cmd->add_option("topic", o.topic, "topic: /name, name or rt/name")->required();
  add_domain_option(cmd, o.domain);
  cmd->add_option("--wait", o.wait_s, "seconds to wait for a publisher")
      ->capture_default_str()
      ->check_range(0, 3600);
  cmd->add_option("--duration", o.duration_s, "stop after this many seconds (0: until Ctrl-C)")
      ->check_range(0, 1e9);
}

bool should_stop(const CommonOptions& o, Clock::time_point start) {
  if (stop_requested()) return true;
  return o.duration_s > 0 && Clock::now() - start > std::chrono::duration<double>(o.duration_s);
}

void run_list(const CommonOptions& o, bool verbose) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  const auto topics =
      discover(participant, std::chrono::milliseconds(static_cast<int>(o.wait_s * 1000)));
  for (const auto& [name, info] : topics) {
    // Services (rq/..Request, rr/..Reply: the parameter services) are not topics, as in
    // `ros2 topic list`; `avs param list` shows the nodes that offer them.
    if (name.rfind("rq/", 0) == 0 || name.rfind("rr/", 0) == 0) continue;
    // Nor is the DDS-only ros_discovery_info (ros2 topic list hides it too); -v shows it.
    if (!verbose && name == "ros_discovery_info") continue;
    // ROS names (`/chatter`) as ros2 topic list prints them; the DDS ones with -v.
    const std::string ros_name =
        name.rfind("rt/", 0) == 0 ? runtime::from_dds_topic_name(name) : name;
    std::printf("%-32s %-44s %zu pub, %zu sub\n", ros_name.c_str(),
                runtime::to_ros_type_name(info.type_name).c_str(), info.publishers.size(),
                info.subscribers.size());
    if (!verbose) continue;
    std::printf("    DDS topic: %s\n    DDS type: %s\n", name.c_str(), info.type_name.c_str());
    for (const auto& p : info.publishers) std::printf("    publisher:  %s\n", p.qos.c_str());
    for (const auto& s : info.subscribers) std::printf("    subscriber: %s\n", s.qos.c_str());
  }
  if (topics.empty()) std::fprintf(stderr, "no topics found on domain %d\n", o.domain);
}

/// The publishers and subscribers of o.topic, waiting up to o.wait_s for the first one.
TopicInfo find_topic(const runtime::dds::Participant& participant, const CommonOptions& o) {
  const std::string dds_name = dds_topic_of(o.topic);
  const auto deadline = Clock::now() + std::chrono::duration<double>(o.wait_s);
  for (;;) {
    const auto topics = discover(participant, std::chrono::milliseconds(300));
    if (const auto it = topics.find(dds_name); it != topics.end()) return it->second;
    if (Clock::now() > deadline) {
      throw runtime::Error("no publisher or subscriber of " +
                           runtime::from_dds_topic_name(dds_name) + " on domain " +
                           std::to_string(o.domain) + " within " +
                           runtime::format_number(o.wait_s) + " s (--wait)");
    }
  }
}

/// "01.0f.7e..." as ros2 topic info -v prints a GID.
std::string gid_text(const runtime::Gid& gid) {
  std::string out;
  char byte[4];
  for (std::size_t i = 0; i < gid.size(); ++i) {
    std::snprintf(byte, sizeof byte, i == 0 ? "%02x" : ".%02x", gid[i]);
    out += byte;
  }
  return out;
}

/// As `ros2 topic info [-v]`: the type, the endpoint counts, with -v each endpoint's node
/// (from ros_discovery_info, as ros2 reads it), endpoint type, GID and QoS, and the DDS names.
void run_info(const CommonOptions& o, bool verbose) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  const TopicInfo info = find_topic(participant, o);
  std::printf("Type: %s\nPublisher count: %zu\nSubscription count: %zu\n",
              runtime::to_ros_type_name(info.type_name).c_str(), info.publishers.size(),
              info.subscribers.size());
  if (!verbose) return;
  std::printf("DDS topic: %s\nDDS type: %s\n", dds_topic_of(o.topic).c_str(),
              info.type_name.c_str());
  // Which node each endpoint belongs to: ros_discovery_info (transient local: at once).
  std::map<runtime::Gid, std::pair<std::string, std::string>> node_of;  // namespace, name
  for (const auto& p : runtime::read_ros_discovery(participant, std::chrono::milliseconds(1000))) {
    for (const auto& n : p.nodes) {
      for (const auto* gids : {&n.readers, &n.writers}) {
        for (const auto& g : *gids) node_of[g] = {n.node_namespace, n.node_name};
      }
    }
  }
  for (const auto* side : {&info.publishers, &info.subscribers}) {
    const bool publishers = side == &info.publishers;
    std::printf("%s:\n", publishers ? "Publishers" : "Subscriptions");
    for (const auto& e : *side) {
      const auto node = node_of.find(e.gid);
      std::printf("  Node name: %s\n  Node namespace: %s\n  Endpoint type: %s\n  GID: %s\n",
                  node != node_of.end() ? node->second.second.c_str() : "_NODE_NAME_UNKNOWN_",
                  node != node_of.end() ? node->second.first.c_str()
                                        : "_NODE_NAMESPACE_UNKNOWN_",
                  publishers ? "PUBLISHER" : "SUBSCRIPTION", gid_text(e.gid).c_str());
      std::printf("  QoS: %s\n", e.qos.c_str());
    }
  }
}

void run_echo(const CommonOptions& o, const introspection::YamlOptions& yaml) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  RawReader reader(participant, o.topic, o.wait_s);
  const auto& types = introspection::built_in_types();
  const auto start = Clock::now();
  long printed = 0;
  while (!should_stop(o, start) && (o.count == 0 || printed < o.count)) {
    reader.take(std::chrono::milliseconds(100), [&](std::span<const std::uint8_t> bytes,
                                                    const dds_sample_info_t&) {
      if (o.count != 0 && printed >= o.count) return;
      const auto value = introspection::decode_cdr(types, reader.type().dds_name, bytes);
      std::fputs(introspection::to_yaml(value, yaml).c_str(), stdout);
      std::fputs("---\n", stdout);
      std::fflush(stdout);
      ++printed;
    });
  }
}

/// Rate and bandwidth over a sliding window of receive times.
void run_rate(const CommonOptions& o, bool bandwidth, std::size_t window) {
  runtime::dds::Participant participant(o.domain, environment_partition());
  RawReader reader(participant, o.topic, o.wait_s);
  std::deque<std::pair<Clock::time_point, std::size_t>> samples;
  std::uint64_t total = 0;
  const auto start = Clock::now();
  auto next_print = start + std::chrono::seconds(1);
  auto report = [&] {
    if (samples.size() < 2) {
      std::printf("no new messages\n");
      return;
    }
    std::vector<double> dt;
    std::size_t bytes = 0;
    for (std::size_t i = 1; i < samples.size(); ++i) {
      dt.push_back(std::chrono::duration<double>(samples[i].first - samples[i - 1].first).count());
      bytes += samples[i].second;
    }
    double mean = 0;
    for (double d : dt) mean += d;
    mean /= static_cast<double>(dt.size());
    double var = 0;
    for (double d : dt) var += (d - mean) * (d - mean);
    const double stddev = std::sqrt(var / static_cast<double>(dt.size()));
    const auto [min_it, max_it] = std::minmax_element(dt.begin(), dt.end());
    const double span_s =
        std::chrono::duration<double>(samples.back().first - samples.front().first).count();
    if (bandwidth) {
      const double bps = static_cast<double>(bytes) / span_s;
      std::printf("%.3f MB/s from %zu messages, mean size %.0f B (min %zu B max %zu B)\n",
                  bps / 1e6, samples.size(),
                  static_cast<double>(bytes) / static_cast<double>(dt.size()),
                  std::min_element(samples.begin(), samples.end(),
                                   [](auto& a, auto& b) { return a.second < b.second; })
                      ->second,
                  std::max_element(samples.begin(), samples.end(), [](auto& a, auto& b) {
                    return a.second < b.second;
                  })->second);
    } else {
      std::printf("average rate: %.3f Hz\n\tmin: %.6fs max: %.6fs std dev: %.6fs window: %zu\n",
                  1.0 / mean, *min_it, *max_it, stddev, samples.size());
    }
    std::fflush(stdout);
  };
  while (!should_stop(o, start)) {
    reader.take(std::chrono::milliseconds(50),
                [&](std::span<const std::uint8_t> bytes, const dds_sample_info_t&) {
                  samples.emplace_back(Clock::now(), bytes.size());
                  ++total;
                  if (samples.size() > window) samples.pop_front();
                });
    if (Clock::now() >= next_print) {
      report();
      next_print += std::chrono::seconds(1);
    }
  }
  if (total == 0) throw runtime::Error("no message received on " + reader.dds_name());
}

}  // namespace

void add_topic_command(Command& app) {
  auto* topic =
      app.add_subcommand("topic", "Inspect topics of running graphs (any process, any host)");
  topic->require_subcommand(1);

  static CommonOptions list_o;
  static bool verbose = false;
  list_o.wait_s = 1.5;
  auto* list = topic->add_subcommand(
      "list", "Topics seen through DDS discovery, with types and endpoint counts");
  add_common(list, list_o, false);
  list->add_flag("-v,--verbose", verbose, "show DDS type names and each endpoint's QoS");
  list->callback([] {
    stop_on_interrupt();
    run_list(list_o, verbose);
  });

  static CommonOptions info_o;
  static bool info_verbose = false;
  info_o.wait_s = 1.5;
  auto* info = topic->add_subcommand(
      "info", "Type and publisher / subscription counts of a topic (-v: each one's QoS)");
  add_common(info, info_o, true);
  info->add_flag("-v,--verbose", info_verbose, "each endpoint's QoS, the DDS names");
  info->callback([] {
    stop_on_interrupt();
    run_info(info_o, info_verbose);
  });

  static CommonOptions type_o;
  type_o.wait_s = 1.5;
  auto* type = topic->add_subcommand("type", "The message type of a topic (ROS name)");
  add_common(type, type_o, true);
  type->callback([] {
    stop_on_interrupt();
    runtime::dds::Participant participant(type_o.domain, environment_partition());
    std::printf("%s\n",
                runtime::to_ros_type_name(find_topic(participant, type_o).type_name).c_str());
  });

  add_topic_pub_command(topic);

  static CommonOptions echo_o;
  static introspection::YamlOptions yaml;
  auto* echo =
      topic->add_subcommand("echo", "Print samples as YAML (images and clouds summarised)");
  add_common(echo, echo_o, true);
  echo->add_option("-n,--count", echo_o.count, "print this many samples, then exit (0: all)")
      ->check_range(0, 1e12);
  echo->add_option("--max-elements", yaml.max_list_elements,
                   "longest list printed in full (0: all)")
      ->check_range(0, 1e9);
  echo->callback([] {
    stop_on_interrupt();
    run_echo(echo_o, yaml);
  });

  static CommonOptions hz_o;
  static std::size_t hz_window = 1000;
  auto* hz = topic->add_subcommand("hz", "Receive rate: mean, min/max/std of intervals");
  add_common(hz, hz_o, true);
  hz->add_option("-w,--window", hz_window, "intervals in the sliding window")
      ->capture_default_str()
      ->check_range(1, 1e7);
  hz->callback([] {
    stop_on_interrupt();
    run_rate(hz_o, false, hz_window);
  });

  static CommonOptions bw_o;
  static std::size_t bw_window = 1000;
  auto* bw = topic->add_subcommand("bw", "Bandwidth: bytes per second of serialised samples");
  add_common(bw, bw_o, true);
  bw->add_option("-w,--window", bw_window, "messages in the sliding window")
      ->capture_default_str()
      ->check_range(1, 1e7);
  bw->callback([] {
    stop_on_interrupt();
    run_rate(bw_o, true, bw_window);
  });
}

}  // namespace avs::cli
