// sim_amplifier: the simulated pan/tilt head behind its servo amplifiers (issue 3 item 4).
// Hosts an AmplifierServer (Modbus TCP, one unit per axis) whose drives are stepped from a
// container timer at plant_rate_hz ON THE CONTAINER CLOCK: in sim lockstep the plant advances
// only with simulated time, so a run depends on the graph alone. The server's I/O thread
// answers requests with the current drive state under the server's lock; stepping happens only
// in the timer. Publishes the true head state on /sim/head_state and runs a fault schedule
// (silence, drive fault, dropped connections) on the container clock for tests.
#include <cmath>
#include <memory>

#include "avs/runtime/component.hpp"
#include "avs/servo/amplifier_server.hpp"

namespace avs::servo {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

namespace {

/// A one-shot event at `at_s` of the container clock; negative = never.
struct Event {
  double at_s = -1;
  bool done = false;
  bool due(double now_s) {
    if (done || at_s < 0 || now_s < at_s) return false;
    done = true;
    return true;
  }
};

}  // namespace

class SimAmplifier final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    // Defaults from the cores: the server's and the two drives' configs.
    const AmplifierServerConfig server;
    const SimulatedDriveConfig pan = pan_drive_config();
    const SimulatedDriveConfig tilt = tilt_drive_config();
    return {
        .type = "sim_amplifier",
        .description =
            "simulated pan/tilt head behind two torque-mode CiA 402 amplifiers "
            "(Modbus TCP server, unit 1 pan, unit 2 tilt), stepped on the container "
            "clock; fault injection schedule for tests",
        .parameters =
            {ParamSpec::string("bind_address", server.bind_address,
                               "address the Modbus server binds"),
             ParamSpec::integer("port", sim_amplifier_default_port, 1, 65535, "",
                                "Modbus TCP port"),
             ParamSpec::integer("pan_unit_id", pan.unit_id, 1, 247, "",
                                "Modbus unit id of the pan drive"),
             ParamSpec::integer("tilt_unit_id", tilt.unit_id, 1, 247, "",
                                "Modbus unit id of the tilt drive"),
             ParamSpec::real("plant_rate_hz", 1.0 / server.step_period_s, 100.0, 100000.0, "Hz",
                             "drive/plant stepping rate on the container clock (the plant "
                             "integrates with sub-steps <= 0.1 ms inside each step)"),
             ParamSpec::real("publish_rate_hz", 1000.0, 1.0, 100000.0, "Hz",
                             "/sim/head_state rate (at most the plant rate)"),
             ParamSpec::real("watchdog_timeout_s", pan.watchdog_timeout_s, 0.0, 10.0, "s",
                             "drive-side watchdog: no command for this long -> fault 0x8130 "
                             "(0 = off)"),
             ParamSpec::real("initial_pan_rad", pan.initial_q_rad, -3.2, 3.2, "rad",
                             "pan angle at start"),
             ParamSpec::real("initial_tilt_rad", tilt.initial_q_rad, -1.6, 1.6, "rad",
                             "tilt angle at start"),
             ParamSpec::real("tilt_gravity_nm", tilt.plant.gravity_nm, 0.0, 10.0, "N m",
                             "m g l of an unbalanced tilt axis (0 = balanced)"),
             ParamSpec::real("silent_from_s", -1.0, -1.0, std::nullopt, "s",
                             "fault injection: stop answering requests at this container time "
                             "(-1 = never)"),
             ParamSpec::real("silent_until_s", -1.0, -1.0, std::nullopt, "s",
                             "answer again from this time (-1 = stay silent)"),
             ParamSpec::real("fault_at_s", -1.0, -1.0, std::nullopt, "s",
                             "fault injection: raise a latched drive fault 0x5000 (-1 = never)"),
             ParamSpec::integer("fault_axis", 0, 0, 1, "", "axis of fault_at_s: 0 pan, 1 tilt"),
             ParamSpec::real("drop_connections_at_s", -1.0, -1.0, std::nullopt, "s",
                             "fault injection: close every client connection (-1 = never)")},
        .publishes = {runtime::port<msgs::sensor_msgs::JointState>("head_state",
                                                                   "/sim/head_state")},
        .subscribes = {}};
  }

  explicit SimAmplifier(ComponentContext& ctx)
      : Component(ctx),
        head_state_(ctx.publisher<msgs::sensor_msgs::JointState>("head_state")),
        plant_rate_hz_(ctx.param<double>("plant_rate_hz")),
        silent_from_(Event{ctx.param<double>("silent_from_s")}),
        silent_until_(Event{ctx.param<double>("silent_until_s")}),
        fault_at_(Event{ctx.param<double>("fault_at_s")}),
        drop_at_(Event{ctx.param<double>("drop_connections_at_s")}),
        fault_axis_(static_cast<std::size_t>(ctx.param<std::int64_t>("fault_axis"))) {
    const double publish_rate = std::min(ctx.param<double>("publish_rate_hz"), plant_rate_hz_);
    publish_every_ = std::max<std::int64_t>(1, std::llround(plant_rate_hz_ / publish_rate));
    AmplifierServerConfig config;
    config.bind_address = ctx.param<std::string>("bind_address");
    config.port = ctx.param<int>("port");
    config.clock = ClockMode::external;
    SimulatedDriveConfig pan = pan_drive_config(ctx.param<int>("pan_unit_id"));
    SimulatedDriveConfig tilt = tilt_drive_config(ctx.param<int>("tilt_unit_id"));
    if (pan.unit_id == tilt.unit_id) {
      throw std::invalid_argument("pan_unit_id and tilt_unit_id are both " +
                                  std::to_string(pan.unit_id));
    }
    pan.initial_q_rad = ctx.param<double>("initial_pan_rad");
    tilt.initial_q_rad = ctx.param<double>("initial_tilt_rad");
    tilt.plant.gravity_nm = ctx.param<double>("tilt_gravity_nm");
    pan.watchdog_timeout_s = tilt.watchdog_timeout_s = ctx.param<double>("watchdog_timeout_s");
    config.axes = {pan, tilt};
    // Listening from construction on, so a servo_drive later in the same container can
    // connect while it is being configured.
    server_ = std::make_unique<AmplifierServer>(config);
    log().info("simulated amplifiers on ", config.bind_address, ":", server_->port(), " (pan unit ",
               pan.unit_id, ", tilt unit ", tilt.unit_id, "), plant at ", plant_rate_hz_,
               " Hz on the ", ctx.uses_sim_time() ? "simulated" : "wall", " clock");
  }

  void on_activate() override {
    const auto period =
        runtime::Duration(static_cast<std::int64_t>(std::llround(1e9 / plant_rate_hz_)));
    dt_s_ = static_cast<double>(period.count()) * 1e-9;
    timer_ = context().create_timer(period, [this] { tick(); });
  }

  void on_deactivate() override {
    const ServerCounters c = server_->counters();
    log().info("served ", c.replies, " replies to ", c.requests, " requests (", c.dropped_requests,
               " dropped while silent, ", c.exceptions, " exceptions, ", c.connections_accepted,
               " connections)");
  }

 private:
  void tick() {
    const double now_s = context().now().seconds();
    if (silent_from_.due(now_s)) {
      server_->set_silent(true);
      log().warn("fault injection: amplifiers silent from t = ", now_s, " s");
    }
    if (silent_until_.due(now_s)) {
      server_->set_silent(false);
      log().info("fault injection: amplifiers answer again at t = ", now_s, " s");
    }
    if (fault_at_.due(now_s)) {
      server_->raise_drive_fault(fault_axis_, error_code_injected, true);
      log().warn("fault injection: drive fault 0x5000 on axis ", fault_axis_, " at t = ", now_s,
                 " s");
    }
    if (drop_at_.due(now_s)) server_->drop_connections();

    server_->step(dt_s_);
    if (++steps_ % publish_every_ != 0) return;
    publish_state();
  }

  void publish_state() {
    auto msg = head_state_.loan();  // every field set below
    runtime::to_ros_time(context().now(), msg->header.stamp);
    runtime::set_string(msg->header.frame_id, "head");
    runtime::resize_sequence(msg->name, 2);
    runtime::resize_sequence(msg->position, 2);
    runtime::resize_sequence(msg->velocity, 2);
    runtime::resize_sequence(msg->effort, 2);
    static const char* const names[2] = {"pan", "tilt"};
    for (std::size_t axis = 0; axis < 2; ++axis) {
      runtime::set_string(msg->name._buffer[axis], names[axis]);
      server_->with_drive(axis, [&](SimulatedDrive& drive) {
        const AxisPlantState& s = drive.plant().state();
        msg->position._buffer[axis] = s.q_rad;
        msg->velocity._buffer[axis] = s.qd_rad_s;
        msg->effort._buffer[axis] = s.motor_torque_nm;
      });
    }
    head_state_.publish(std::move(msg));
  }

  runtime::Publisher<msgs::sensor_msgs::JointState> head_state_;
  double plant_rate_hz_;
  double dt_s_ = 0.001;
  std::int64_t publish_every_ = 1;
  std::int64_t steps_ = 0;
  Event silent_from_;
  Event silent_until_;
  Event fault_at_;
  Event drop_at_;
  std::size_t fault_axis_;
  std::unique_ptr<AmplifierServer> server_;
  runtime::TimerId timer_ = 0;
};

AVS_REGISTER_COMPONENT(SimAmplifier);

}  // namespace avs::servo
