// avs head reset|estop: requests to the servo drive. `reset` asks it to reset latched drive
// faults (docs/servo.md section 4) with one message on /head/fault_reset (reliable, volatile: a
// reset is never kept for a later subscriber); `estop on|off` engages or releases the e-stop on
// /head/estop (transient local). Topic, type and QoS are those of servo_drive's ports, read
// from the component registry, so these commands and the component cannot disagree. Each waits
// for a subscriber first and for the subscriber's acknowledgement after.
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "avs/msg/type_registry.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"

namespace avs::cli {

namespace {

struct RequestOptions {
  int domain = 0;  // add_domain_option
  double wait_s = 5.0;
  std::string topic;  // empty: servo_drive's default topic
};

/// One request to servo_drive on its port `port_name`: waits for the drive's subscriber, sends
/// the sample `fill` writes, waits for every matched reader's acknowledgement. With `hold`,
/// keeps the writer (and so a transient-local sample) until Ctrl-C. 0 on success.
int send_request(const char* command, const char* port_name, const RequestOptions& o,
                 const std::function<void(unsigned char*)>& fill, const std::string& done,
                 bool hold) {
  const runtime::RegisteredComponent* drive =
      runtime::ComponentRegistry::instance().find("servo_drive");
  const runtime::PortSpec* port = drive != nullptr ? drive->spec.find_port(port_name) : nullptr;
  if (port == nullptr) {
    std::fprintf(stderr, "avs head %s: this avs was built without servo_drive\n", command);
    return 1;
  }
  const msg::TypeEntry* type = msg::find_type(port->dds_type);
  if (type == nullptr) {
    std::fprintf(stderr, "avs head %s: unknown type %s\n", command, port->dds_type.c_str());
    return 1;
  }
  const std::string ros_topic =
      runtime::resolve_topic_name("/", o.topic.empty() ? port->default_topic : o.topic);
  const std::string dds_topic = runtime::to_dds_topic_name(ros_topic);

  runtime::dds::Participant participant(o.domain, environment_partition());
  runtime::dds::Topic topic(participant, type->descriptor, dds_topic, port->qos);
  // The port's own QoS: /head/estop's reader is transient local, which a volatile writer
  // (a default `ros2 topic pub`) would not even match.
  runtime::dds::Writer writer(participant, topic, port->qos);
  if (hold) stop_on_interrupt();
  // 1. A subscriber must be there: a message sent to nobody is lost.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(o.wait_s);
  while (writer.matched_readers() == 0) {
    if (std::chrono::steady_clock::now() > deadline || (hold && stop_requested())) {
      std::fprintf(stderr,
                   "avs head %s: no subscriber of %s on domain %d within %.1f s (is "
                   "servo_drive running?)\n",
                   command, ros_topic.c_str(), o.domain, o.wait_s);
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // 2. One request, acknowledged by every matched reader.
  std::vector<unsigned char> sample(type->sample_size, 0);
  fill(sample.data());
  writer.write(sample.data());
  const dds_return_t acked = dds_wait_for_acks(writer.get(), DDS_SECS(o.wait_s > 0 ? o.wait_s : 1));
  if (acked != DDS_RETCODE_OK) {
    std::fprintf(stderr, "avs head %s: the request on %s was not acknowledged within %.1f s\n",
                 command, ros_topic.c_str(), o.wait_s);
    return 1;
  }
  std::printf("%s on %s (%u subscriber%s)\n", done.c_str(), ros_topic.c_str(),
              writer.matched_readers(), writer.matched_readers() == 1 ? "" : "s");
  if (hold) {
    std::printf("holding it for drives that start later; Ctrl-C to stop\n");
    std::fflush(stdout);
    while (!stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

void add_request_options(Command* cmd, RequestOptions& o, const char* default_topic) {
  add_domain_option(cmd, o.domain);
  cmd->add_option("--wait", o.wait_s,
                  "seconds to wait for a subscriber and for its acknowledgement")
      ->capture_default_str()
      ->check_range(0, 3600);
  cmd->add_option("--topic", o.topic,
                  std::string("topic, if remapped in the graph (default: servo_drive's ") +
                      default_topic + ")");
}

void add_head_command(Command& app) {
  auto* head = app.add_subcommand("head", "Commands to the pan/tilt head's servo drive");
  head->require_subcommand(1);

  static RequestOptions reset_options;
  auto* reset = head->add_subcommand(
      "reset",
      "Request a fault reset: servo_drive resets drives in Fault and, once they have been "
      "Operation enabled for fault_clear_stable_cycles, applies torque again (docs/servo.md)");
  add_request_options(reset, reset_options, "/head/fault_reset");
  reset->callback([] {
    exit_status() = send_request(
        "reset", "fault_reset", reset_options, [](unsigned char*) {}, "fault reset requested",
        false);  // Empty: all zero
  });

  static RequestOptions estop_options;
  static std::string estop_state;
  static bool estop_hold = false;
  auto* estop = head->add_subcommand(
      "estop",
      "Engage (on) or release (off) the e-stop: servo_drive goes to zero torque within one "
      "period and ignores commands until released (docs/servo.md)");
  estop->add_option("state", estop_state, "on or off")->required()->check_member({"on", "off"});
  add_request_options(estop, estop_options, "/head/estop");
  estop->add_flag("--hold", estop_hold,
                  "keep the e-stop sample published (transient local) until Ctrl-C, so that a "
                  "servo_drive started later receives it too");
  estop->callback([] {
    const bool on = estop_state == "on";
    exit_status() = send_request(
        "estop", "estop", estop_options,
        [on](unsigned char* sample) { *sample = on ? 1 : 0; },  // std_msgs/Bool: one byte
        on ? "e-stop engaged" : "e-stop released", estop_hold);
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_head_command)

}  // namespace avs::cli
