// avs topic pub: one message (or a stream) of any type in idl/ from YAML, with the QoS the
// topic's subscribers need unless told otherwise (a transient-local subscriber such as
// servo_drive's /head/estop does not match a volatile publisher).
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "avs/introspection/cdr_writer.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/msg/type_registry.hpp"
#include "avs/runtime/parameters.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"

namespace avs::cli {

namespace {

using Clock = std::chrono::steady_clock;
using runtime::dds::EndpointQos;

struct PubOptions {
  std::string topic;
  std::string type;
  std::string message;
  int domain = 0;  // add_domain_option
  double rate_hz = 1.0;
  bool once = false;
  long times = 0;  // 0: until Ctrl-C
  double wait_s = 5.0;
  std::string reliability;  // "" = from the subscribers
  std::string durability;
  int depth = 0;  // 0 = from the subscribers
};

/// The QoS every subscriber of `dds_topic` requests (DDS discovery), waiting up to `wait` for
/// the first one. Throws when one of them uses another type.
std::vector<EndpointQos> subscribers_of(const runtime::dds::Participant& participant,
                                        const std::string& dds_topic, const std::string& dds_type,
                                        Clock::duration wait) {
  runtime::dds::Entity subs(runtime::check_dds(
      dds_create_reader(participant.get(), DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr),
      "read DCPSSubscription"));
  const auto deadline = Clock::now() + wait;
  std::vector<EndpointQos> found;
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    found.clear();
    void* samples[256] = {};
    dds_sample_info_t infos[256];
    const int n =
        runtime::check_dds(dds_read(subs.get(), samples, infos, 256, 256), "read discovery");
    std::string other_type;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data || infos[i].instance_state != DDS_IST_ALIVE) continue;
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (dds_topic != ep->topic_name) continue;
      if (dds_type != ep->type_name) other_type = ep->type_name;
      found.push_back(EndpointQos::from_dds(ep->qos));
    }
    if (n > 0) dds_return_loan(subs.get(), samples, n);
    if (!other_type.empty()) {
      throw runtime::Error(runtime::from_dds_topic_name(dds_topic) + " is subscribed as " +
                           runtime::to_ros_type_name(other_type) + ", not " +
                           runtime::to_ros_type_name(dds_type));
    }
    if (stop_requested()) throw runtime::Error("interrupted");
  } while (found.empty() && Clock::now() < deadline);
  return found;
}

/// The QoS to publish with and why: what the options say, else what the subscribers need
/// (reliable; transient local when one asks for it, with depth 1 so that a late subscriber gets
/// the last message only; else volatile, keep last 10).
std::pair<EndpointQos, std::string> choose_qos(const PubOptions& o,
                                               const std::vector<EndpointQos>& subscribers) {
  EndpointQos q;
  q.reliable = true;
  std::string why = subscribers.empty() ? "no subscriber seen" : "what the subscribers need";
  for (const auto& s : subscribers) q.transient_local = q.transient_local || s.transient_local;
  q.depth = q.transient_local ? 1 : 10;
  if (!o.reliability.empty()) q.reliable = o.reliability == "reliable";
  if (!o.durability.empty()) q.transient_local = o.durability == "transient_local";
  if (o.depth > 0) q.depth = o.depth;
  if (!o.reliability.empty() || !o.durability.empty() || o.depth > 0) why = "the --qos options";
  return {q, why};
}

void run_pub(const PubOptions& o) {
  // 1. The type and the message.
  const std::string dds_type =
      o.type.find("::") != std::string::npos ? o.type : introspection::dds_type_name(o.type);
  const msg::TypeEntry* type = msg::find_type(dds_type);
  if (type == nullptr) {
    throw runtime::Error("unknown type '" + o.type +
                         "': avs publishes the types in idl/ (ROS names such as "
                         "std_msgs/msg/Bool; `avs topic type TOPIC` tells a topic's)");
  }
  YAML::Node yaml;
  try {
    yaml = YAML::Load(o.message.empty() ? std::string("{}") : o.message);
  } catch (const YAML::Exception& e) {
    throw runtime::Error("the message is not YAML: " + std::string(e.what()));
  }
  std::vector<std::uint8_t> cdr;
  try {
    cdr = introspection::encode_cdr(introspection::built_in_types(), dds_type, yaml);
  } catch (const introspection::EncodeError& e) {
    throw runtime::Error(runtime::to_ros_type_name(dds_type) + ": " + e.what());
  }
  const std::string ros_topic = o.topic.rfind("rt/", 0) == 0
                                    ? runtime::from_dds_topic_name(o.topic)
                                    : runtime::resolve_topic_name("/", o.topic);
  const std::string dds_topic = runtime::to_dds_topic_name(ros_topic);

  // 2. QoS: what the subscribers need, said.
  runtime::dds::Participant participant(o.domain, environment_partition());
  const auto subscribers = subscribers_of(
      participant, dds_topic, dds_type,
      std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(std::min(o.wait_s, o.once ? o.wait_s : 1.0))));
  const auto [qos, why] = choose_qos(o, subscribers);
  std::fprintf(stderr, "avs topic pub: %s %s with %s (%s)\n", ros_topic.c_str(),
               runtime::to_ros_type_name(dds_type).c_str(), qos.describe().c_str(), why.c_str());
  std::size_t incompatible = 0;
  for (const auto& s : subscribers) {
    incompatible += (s.reliable && !qos.reliable) || (s.transient_local && !qos.transient_local);
  }
  if (incompatible > 0) {
    std::fprintf(stderr,
                 "avs topic pub: warning: %zu subscriber(s) ask for more (reliable or "
                 "transient_local) and will not receive these messages\n",
                 incompatible);
  }

  // 3. Publish.
  runtime::dds::RawWriter writer(participant, *type, dds_topic, qos);
  const auto bytes = std::as_bytes(std::span(cdr));
  const auto wait_deadline = Clock::now() + std::chrono::duration<double>(o.wait_s);
  const std::size_t expected = subscribers.size() - incompatible;
  if (o.once) {
    while (writer.matched_readers() < std::max<std::size_t>(expected, 1)) {
      if (Clock::now() > wait_deadline) {
        if (writer.matched_readers() > 0) break;
        throw runtime::Error("no subscriber of " + ros_topic + " matched within " +
                             runtime::format_number(o.wait_s) + " s (--wait)");
      }
      if (stop_requested()) throw runtime::Error("interrupted");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    writer.write(bytes);
    if (qos.reliable &&
        dds_wait_for_acks(writer.get(), DDS_SECS(static_cast<std::int64_t>(o.wait_s) + 1)) !=
            DDS_RETCODE_OK) {
      throw runtime::Error("the message on " + ros_topic + " was not acknowledged within " +
                           runtime::format_number(o.wait_s) + " s");
    }
    std::printf("published 1 message on %s to %u subscriber%s\n", ros_topic.c_str(),
                writer.matched_readers(), writer.matched_readers() == 1 ? "" : "s");
    return;
  }
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate_hz));
  auto next = Clock::now();
  for (long n = 1; o.times == 0 || n <= o.times; ++n) {
    if (stop_requested()) break;
    writer.write(bytes);
    std::printf("publishing #%ld on %s (%u subscriber%s)\n", n, ros_topic.c_str(),
                writer.matched_readers(), writer.matched_readers() == 1 ? "" : "s");
    std::fflush(stdout);
    next += period;
    while (Clock::now() < next && !stop_requested()) {
      std::this_thread::sleep_for(
          std::min<Clock::duration>(next - Clock::now(), std::chrono::milliseconds(50)));
    }
  }
  if (qos.reliable) dds_wait_for_acks(writer.get(), DDS_SECS(1));
}

}  // namespace

void add_topic_pub_command(Command* topic) {
  static PubOptions o;
  auto* pub = topic->add_subcommand(
      "pub", "Publish a message of any type in idl/, written as YAML, once or at a rate");
  pub->add_option("topic", o.topic, "topic: /name, name or rt/name")->required();
  pub->add_option("type", o.type, "message type: std_msgs/msg/Bool (or its DDS name)")->required();
  pub->add_option("message", o.message,
                  "the fields as YAML, e.g. '{data: true}'; fields left out are zero (default {})");
  add_domain_option(pub, o.domain);
  pub->add_flag(
      "-1,--once", o.once,
      "publish one message once a subscriber matched, wait for its acknowledgement, exit");
  pub->add_option("-r,--rate", o.rate_hz, "messages per second")
      ->check_range(1e-3, 1e5)
      ->capture_default_str();
  pub->add_option("-t,--times", o.times, "publish this many messages, then exit (0: until Ctrl-C)")
      ->check_range(0, 1e12);
  pub->add_option("-w,--wait", o.wait_s,
                  "seconds to wait for subscribers (--once: for one to match and acknowledge)")
      ->check_range(0, 3600)
      ->capture_default_str();
  pub->add_option("--qos-reliability", o.reliability, "default: reliable")
      ->check_member({"reliable", "best_effort"});
  pub->add_option("--qos-durability", o.durability,
                  "default: transient_local if a subscriber asks for it, else volatile")
      ->check_member({"volatile", "transient_local"});
  pub->add_option("--qos-depth", o.depth, "keep-last depth (default: 1 transient local, else 10)")
      ->check_range(1, 100000);
  pub->footer(
      "Example: avs topic pub /head/estop std_msgs/msg/Bool '{data: true}' --once (the e-stop; "
      "'{data: false}' releases it). The QoS chosen is printed on stderr.");
  pub->callback([] {
    stop_on_interrupt();
    run_pub(o);
  });
}

}  // namespace avs::cli
