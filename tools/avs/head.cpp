// avs head reset: asks the servo drive to reset latched drive faults (docs/servo.md section 4)
// with one message on /head/fault_reset. The topic, type and QoS are those of servo_drive's
// `fault_reset` port, read from the component registry, so this command and the component
// cannot disagree. It waits for a subscriber first and for the subscriber's acknowledgement
// after (the topic is reliable and volatile: a reset is never kept for a later subscriber).
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "avs/msg/type_registry.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"

namespace avs::cli {

namespace {

struct ResetOptions {
  int domain = 0;  // add_domain_option
  double wait_s = 5.0;
  std::string topic;  // empty: servo_drive's default topic
};

int run_reset(const ResetOptions& o) {
  const runtime::RegisteredComponent* drive =
      runtime::ComponentRegistry::instance().find("servo_drive");
  const runtime::PortSpec* port = drive != nullptr ? drive->spec.find_port("fault_reset") : nullptr;
  if (port == nullptr) {
    std::fprintf(stderr, "avs head reset: this avs was built without servo_drive\n");
    return 1;
  }
  const msg::TypeEntry* type = msg::find_type(port->dds_type);
  if (type == nullptr) {
    std::fprintf(stderr, "avs head reset: unknown type %s\n", port->dds_type.c_str());
    return 1;
  }
  const std::string ros_topic =
      runtime::resolve_topic_name("/", o.topic.empty() ? port->default_topic : o.topic);
  const std::string dds_topic = runtime::to_dds_topic_name(ros_topic);

  runtime::dds::Participant participant(o.domain, environment_partition());
  runtime::dds::Topic topic(participant, type->descriptor, dds_topic, port->qos);
  runtime::dds::Writer writer(participant, topic, port->qos);
  // 1. A subscriber must be there: a volatile message sent to nobody is lost.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(o.wait_s);
  while (writer.matched_readers() == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      std::fprintf(stderr,
                   "avs head reset: no subscriber of %s on domain %d within %.1f s (is "
                   "servo_drive running?)\n",
                   ros_topic.c_str(), o.domain, o.wait_s);
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // 2. One request, acknowledged by every matched reader.
  std::vector<unsigned char> sample(type->sample_size, 0);  // Empty: all zero
  writer.write(sample.data());
  const dds_return_t acked = dds_wait_for_acks(writer.get(), DDS_SECS(o.wait_s > 0 ? o.wait_s : 1));
  if (acked != DDS_RETCODE_OK) {
    std::fprintf(stderr, "avs head reset: the reset on %s was not acknowledged within %.1f s\n",
                 ros_topic.c_str(), o.wait_s);
    return 1;
  }
  std::printf("fault reset requested on %s (%u subscriber%s)\n", ros_topic.c_str(),
              writer.matched_readers(), writer.matched_readers() == 1 ? "" : "s");
  return 0;
}

void add_head_command(Command& app) {
  auto* head = app.add_subcommand("head", "Commands to the pan/tilt head's servo drive");
  head->require_subcommand(1);
  static ResetOptions options;
  auto* reset = head->add_subcommand(
      "reset",
      "Request a fault reset: servo_drive resets drives in Fault and, once they have been "
      "Operation enabled for fault_clear_stable_cycles, applies torque again (docs/servo.md)");
  add_domain_option(reset, options.domain);
  reset
      ->add_option("--wait", options.wait_s,
                   "seconds to wait for a subscriber and for its acknowledgement")
      ->capture_default_str()
      ->check_range(0, 3600);
  reset->add_option("--topic", options.topic,
                    "topic, if remapped in the graph (default: servo_drive's /head/fault_reset)");
  reset->callback([] { exit_status() = run_reset(options); });
}

}  // namespace

AVS_REGISTER_COMMAND(add_head_command)

}  // namespace avs::cli
