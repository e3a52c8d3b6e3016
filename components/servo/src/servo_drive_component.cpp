// servo_drive: the only component that talks to the servo amplifiers (issue 5 item 3). Wraps
// DriveClient (Modbus TCP/RTU, CiA 402, safety rules): enable on activate, disable on
// deactivate, one cyclic exchange per period, either
//   * as a container timer (own_thread: false): REQUIRED in sim time, so that a lockstep run
//     is deterministic (the exchange happens at exact simulated instants, in timer order), or
//   * on its own thread (own_thread: true, wall time / real hardware), with an absolute
//     schedule on the steady clock and optional SCHED_FIFO priority.
// Publishes /head/joint_states every good cycle and /head/drive_status at status_rate_hz (and
// at once when the link or fault state changes); takes /head/torque_command, /head/estop and
// /head/fault_reset (the only way to clear a latched fault unless auto_fault_reset).
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "avs/msg/convert.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/runtime/rejections.hpp"
#include "avs/runtime/text.hpp"
#include "avs/servo/amplifier_server.hpp"
#include "avs/servo/drive_client.hpp"
#include "avs/servo/plant.hpp"
#include "avs/servo/register_map_yaml.hpp"

namespace avs::servo {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

namespace {

double element(const std::vector<double>& list, std::size_t i, const std::string& param) {
  if (i >= list.size()) {
    throw ConfigError("servo_drive: parameter '" + param + "' has " + std::to_string(list.size()) +
                      " values, expected one per axis (" + std::to_string(i + 1) + " or more)");
  }
  return list[i];
}

/// The register map(s) of `register_map` (docs/servo.md): a file with one map for every axis,
/// or `axes: {<name>: <map>, ...}` with one map per axis name.
std::vector<RegisterMap> load_maps(const std::string& path, const std::vector<std::string>& names) {
  const YAML::Node root = load_register_map_file(path);
  std::vector<RegisterMap> maps;
  if (root.IsMap() && root["axes"]) {
    const YAML::Node axes = root["axes"];
    for (const std::string& name : names) {
      if (!axes[name]) {
        throw ConfigError(runtime::yaml_location(path, axes.Mark()) + ": axes: no map for axis '" +
                          name + "'");
      }
      maps.push_back(parse_register_map(axes[name], path));
    }
  } else {
    const RegisterMap map = parse_register_map(root, path);
    maps.assign(names.size(), map);
  }
  return maps;
}

}  // namespace

class ServoDrive final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    using runtime::QosProfile;
    QosProfile keep_last_1;
    keep_last_1.depth = 1;
    // Fault reset requests: reliable and volatile, keep last 10 = what a plain ROS 2 publisher
    // offers, so `ros2 topic pub --once /head/fault_reset std_msgs/msg/Empty` matches. Not
    // transient local: an old request must never reset a fault that happens later.
    const QosProfile reset_qos;
    QosProfile estop_qos;
    estop_qos.depth = 1;
    estop_qos.durability = runtime::Durability::transient_local;
    const AxisSafetyConfig any_axis;
    return {
        .type = "servo_drive",
        .description =
            "servo amplifiers over Modbus TCP/RTU (CiA 402, torque mode) with the "
            "host-side safety rules; publishes joint states and drive status",
        .parameters = params().specs_with(
            {ParamSpec::integer("port", sim_amplifier_default_port, 1, 65535, "",
                                "TCP: amplifier port (default: sim_amplifier's)"),
             ParamSpec::string("axis_names", "pan,tilt", "comma-separated joint names, in order"),
             ParamSpec::real_list("unit_ids", {1, 2}, "", "Modbus unit id per axis"),
             ParamSpec::string("register_map", "",
                               "register map YAML file (docs/servo.md); empty = the simulated "
                               "amplifier's map for pan/tilt"),
             ParamSpec::real("response_timeout_s", 0.0, 0.0, 10.0, "s",
                             "Modbus response timeout (wall time); 0 = auto: 0.4 x period / axes "
                             "in wall time, 1 s in sim time (waiting costs no simulated time)"),
             // Per axis (pan, tilt): the head's safety rules, safety.hpp.
             per_axis("max_torque_nm", &AxisSafetyConfig::configured_max_torque_nm, "N m",
                      "configured motor torque limit per axis (also written to the drive's "
                      "max_torque)",
                      0.0, 100.0),
             per_axis("motor_max_torque_nm", &AxisSafetyConfig::motor_max_torque_nm, "N m",
                      "motor peak torque per axis (Table 3)", 0.0, 100.0),
             per_axis("soft_lower_rad", &AxisSafetyConfig::soft_lower_rad, "rad",
                      "soft lower position limit per axis", -1000.0, 1000.0)
                 .live(),
             per_axis("soft_upper_rad", &AxisSafetyConfig::soft_upper_rad, "rad",
                      "soft upper position limit per axis", -1000.0, 1000.0)
                 .live(),
             ParamSpec::real("brake_zone_rad", any_axis.brake_zone_rad, 0.0, 10.0, "rad",
                             "braking zone inside each soft limit")
                 .live(),
             per_axis("brake_gain_nm_s_per_rad", &AxisSafetyConfig::brake_gain_nm_s_per_rad,
                      "N m s/rad", "braking torque per output rad/s toward a nearby limit", 0.0,
                      1000.0)
                 .live(),
             per_axis("output_inertia_kg_m2", &AxisSafetyConfig::output_inertia_kg_m2, "kg m2",
                      "output-side inertia J_eq per axis, for the soft-limit velocity envelope "
                      "(0 = no envelope)",
                      0.0, 1000.0),
             per_axis("gear_ratio", &AxisSafetyConfig::gear_ratio, "",
                      "motor turns per output turn, per axis (envelope)", 0.001, 100000.0),
             per_axis("gear_efficiency", &AxisSafetyConfig::gear_efficiency, "",
                      "gear efficiency per axis (envelope)", 0.01, 1.0),
             ParamSpec::real("envelope_brake_fraction", any_axis.envelope_brake_fraction, 0.0, 1.0,
                             "",
                             "share of the full braking deceleration the velocity envelope "
                             "plans with (the rest is margin); 0 = no envelope")
                 .live(),
             ParamSpec::boolean("own_thread", false,
                                "cycle on a thread of its own (wall time only); false = "
                                "container timer (required in sim time)"),
             ParamSpec::integer("rt_priority", 0, 0, 99, "",
                                "own_thread: SCHED_FIFO priority (0 = normal scheduling)"),
             ParamSpec::real("status_rate_hz", 10.0, 0.1, 1000.0, "Hz", "/head/drive_status rate")
                 .live(),
             ParamSpec::string("report_dir", "",
                               "tests: write <name>.csv (every cycle) and <name>.yaml (summary) "
                               "here on deactivate; empty = none")}),
        .publishes = {runtime::port<msgs::sensor_msgs::JointState>("joint_states",
                                                                   "/head/joint_states"),
                      runtime::port<msgs::avs_msgs::DriveStatus>(
                          "drive_status", "/head/drive_status", keep_last_1)},
        .subscribes = {runtime::port<msgs::avs_msgs::JointTorqueCommand>(
                           "torque_command", "/head/torque_command", keep_last_1),
                       runtime::port<msgs::std_msgs::Bool>("estop", "/head/estop", estop_qos),
                       runtime::port<msgs::std_msgs::Empty>("fault_reset", "/head/fault_reset",
                                                            reset_qos)},
        .default_mismatches = [] { return params().default_mismatches(); }};
  }

  /// Parameters bound to DriveClientConfig (its defaults are the parameters').
  static const runtime::ConfigParams<DriveClientConfig>& params() {
    static const auto p =
        runtime::ConfigParams<DriveClientConfig>()
            .choice("transport", AVS_FIELD(transport),
                    std::vector<std::pair<std::string, Transport>>{{"tcp", Transport::tcp},
                                                                   {"rtu", Transport::rtu}},
                    "Modbus transport")
            .string("host", AVS_FIELD(tcp.host), "TCP: amplifier address")
            .string("rtu_device", AVS_FIELD(rtu.device), "RTU: serial device")
            .integer("rtu_baud", AVS_FIELD(rtu.line.baud), 1200, 12000000, "Bd", "RTU: baud rate")
            .choice("rtu_parity", AVS_FIELD(rtu.line.parity),
                    std::vector<std::pair<std::string, char>>{{"N", 'N'}, {"E", 'E'}, {"O", 'O'}},
                    "RTU: parity")
            .integer("rtu_data_bits", AVS_FIELD(rtu.line.data_bits), 7, 8, "", "RTU: data bits")
            .integer("rtu_stop_bits", AVS_FIELD(rtu.line.stop_bits), 1, 2, "", "RTU: stop bits")
            .boolean("rtu_rs485", AVS_FIELD(rtu.rs485), "RTU: RS-485 serial mode")
            .choice("rtu_rts", AVS_FIELD(rtu.rts),
                    std::vector<std::pair<std::string, int>>{{"none", MODBUS_RTU_RTS_NONE},
                                                             {"up", MODBUS_RTU_RTS_UP},
                                                             {"down", MODBUS_RTU_RTS_DOWN}},
                    "RTU: RTS direction control")
            .integer("rtu_rts_delay_us", AVS_FIELD(rtu.rts_delay_us), -1, 1000000, "us",
                     "RTU: RTS delay (-1 = libmodbus default)")
            .real("rtu_turnaround_s", AVS_FIELD(rtu.drive_turnaround_s), 0.0, 1.0, "s",
                  "RTU: drive reply delay, used by the link budget check")
            .real("cycle_rate_hz", AVS_FIELD(cycle_rate_hz), 1.0, 10000.0, "Hz",
                  "cyclic exchange rate")
            .boolean("use_write_read_0x17", AVS_FIELD(use_write_read_0x17),
                     "one 0x17 write+read per axis, else 0x10 + 0x03")
            .real("command_timeout_s", AVS_FIELD(command_freshness.timeout_s), 0.0001, 10.0, "s",
                  "torque commands whose stamp or arrival is older than this -> zero torque")
            .live()
            .real("command_future_tolerance_s", AVS_FIELD(command_freshness.future_tolerance_s),
                  0.0, 1.0, "s",
                  "torque commands stamped later than their arrival by more than this are "
                  "rejected and counted (sender clock ahead)")
            .live()
            .integer("fault_clear_stable_cycles", AVS_FIELD(fault_clear_stable_cycles), 1, 100000,
                     "",
                     "a drive fault latches zero torque until a reset request and this many "
                     "consecutive cycles of Operation enabled")
            .choice("estop_action", AVS_FIELD(estop_action),
                    std::vector<std::pair<std::string, EstopAction>>{
                        {"disable_operation", EstopAction::disable_operation},
                        {"quick_stop", EstopAction::quick_stop}},
                    "what an e-stop does")
            .live()
            .boolean("auto_fault_reset", AVS_FIELD(auto_fault_reset),
                     "reset drive faults automatically once their cause is gone")
            .live()
            .real("reconnect_backoff_initial_s", AVS_FIELD(reconnect_backoff_initial_s), 0.0001,
                  60.0, "s", "first reconnect delay after a link fault (doubles)")
            .real("reconnect_backoff_max_s", AVS_FIELD(reconnect_backoff_max_s), 0.0001, 600.0, "s",
                  "reconnect delay bound");
    return p;
  }

  /// A per-axis list parameter whose default is the field of the pan and the tilt axis.
  static ParamSpec per_axis(std::string name, double AxisSafetyConfig::*field, std::string unit,
                            std::string description, double min, double max) {
    ParamSpec spec = ParamSpec::real_list(std::move(name),
                                          {pan_safety_config().*field, tilt_safety_config().*field},
                                          std::move(unit), std::move(description));
    spec.min = min;  // each element
    spec.max = max;
    return spec;
  }

  explicit ServoDrive(ComponentContext& ctx)
      : Component(ctx),
        joint_states_(ctx.publisher<msgs::sensor_msgs::JointState>("joint_states")),
        drive_status_(ctx.publisher<msgs::avs_msgs::DriveStatus>("drive_status")),
        own_thread_(ctx.param<bool>("own_thread")),
        rt_priority_(ctx.param<int>("rt_priority")),
        report_dir_(ctx.param<std::string>("report_dir")),
        rejected_(ctx.log(), "/head/torque_command") {
    if (own_thread_ && ctx.uses_sim_time()) {
      throw ConfigError(
          "servo_drive: own_thread: true needs wall time; in sim time the cycle must run as a "
          "container timer (own_thread: false) to stay deterministic");
    }
    DriveClientConfig config = make_config(ctx);
    period_ = runtime::Duration(std::llround(1e9 / config.cycle_rate_hz));
    cycles_per_status_ = status_cycles(ctx.parameters());
    for (const DriveAxisConfig& axis : config.axes) names_.push_back(axis.name);
    client_ = std::make_unique<DriveClient>(std::move(config));  // validates: one-line ConfigError
    try {
      client_->connect();  // configure: word-order probe, mode, drive torque limit
      log().info("connected: ", describe_link());
    } catch (const ConfigError&) {
      throw;  // wrong register map / word order: refuse to load
    } catch (const std::exception& e) {
      log().warn(e.what(), "; retrying from the cyclic exchange with back-off");
    }

    ctx.subscribe<msgs::avs_msgs::JointTorqueCommand>(
        "torque_command",
        [this](runtime::SamplePtr<msgs::avs_msgs::JointTorqueCommand> m) { on_command(*m); });
    ctx.subscribe<msgs::std_msgs::Bool>(
        "estop", [this](runtime::SamplePtr<msgs::std_msgs::Bool> m) { on_estop(m->data); });
    ctx.subscribe<msgs::std_msgs::Empty>(
        "fault_reset", [this](runtime::SamplePtr<msgs::std_msgs::Empty>) { on_fault_reset(); });
  }

  ~ServoDrive() override { stop_thread(); }

  void on_activate() override {
    client_->activate(context().now().seconds());
    if (own_thread_) {
      stop_ = false;
      thread_ = std::thread([this] { thread_loop(); });
    } else {
      timer_ = context().create_timer(period_, [this] { run_cycle(); });
    }
  }

  void on_deactivate() override {
    stop_thread();
    if (timer_ != 0) context().cancel_timer(timer_);
    timer_ = 0;
    client_->deactivate();
    try {
      client_->cycle(context().now().seconds());  // writes torque 0 and Disable operation
    } catch (const std::exception& e) {
      log().warn("deactivate: ", e.what());
    }
    const LinkStatistics s = client_->statistics();
    log().info(cycles_, " cycles, ", s.exchanges, " exchanges, ", link_fault_cycles_,
               " with a link fault, ", s.timeouts, " timeouts, ", s.reconnects, " reconnects");
    write_report(s);
  }

  void on_shutdown() override { client_->disconnect(); }

 private:
  static std::vector<std::string> axis_names(const runtime::ParameterValues& values) {
    return msg::parse_name_list(values.get<std::string>("axis_names"), 0, "axis_names");
  }

  /// Each axis's safety rules from the per-axis parameters (one place for the start-up
  /// configuration and the live changes).
  static std::vector<AxisSafetyConfig> safety_of(const runtime::ParameterValues& values,
                                                 std::size_t axes) {
    const auto list = [&](const char* name) { return values.get<std::vector<double>>(name); };
    const auto max_torque = list("max_torque_nm");
    const auto motor_max = list("motor_max_torque_nm");
    const auto lower = list("soft_lower_rad");
    const auto upper = list("soft_upper_rad");
    const auto brake_gain = list("brake_gain_nm_s_per_rad");
    const auto inertia = list("output_inertia_kg_m2");
    const auto gear_ratio = list("gear_ratio");
    const auto gear_efficiency = list("gear_efficiency");
    std::vector<AxisSafetyConfig> out(axes);
    for (std::size_t i = 0; i < axes; ++i) {
      AxisSafetyConfig& a = out[i];
      a.configured_max_torque_nm = element(max_torque, i, "max_torque_nm");
      a.motor_max_torque_nm = element(motor_max, i, "motor_max_torque_nm");
      a.soft_lower_rad = element(lower, i, "soft_lower_rad");
      a.soft_upper_rad = element(upper, i, "soft_upper_rad");
      a.brake_zone_rad = values.get<double>("brake_zone_rad");
      a.brake_gain_nm_s_per_rad = element(brake_gain, i, "brake_gain_nm_s_per_rad");
      a.output_inertia_kg_m2 = element(inertia, i, "output_inertia_kg_m2");
      a.gear_ratio = element(gear_ratio, i, "gear_ratio");
      a.gear_efficiency = element(gear_efficiency, i, "gear_efficiency");
      a.envelope_brake_fraction = values.get<double>("envelope_brake_fraction");
    }
    return out;
  }

  DriveClientConfig make_config(ComponentContext& ctx) {
    DriveClientConfig c = params().make(ctx.parameters());
    c.tcp.port = ctx.param<int>("port");

    const std::vector<std::string> names = axis_names(ctx.parameters());
    const auto unit_ids = ctx.param<std::vector<double>>("unit_ids");
    const std::vector<AxisSafetyConfig> safety = safety_of(ctx.parameters(), names.size());
    const std::string map_file = ctx.param<std::string>("register_map");
    std::vector<RegisterMap> maps;
    if (!map_file.empty()) {
      maps = load_maps(map_file, names);
    } else {
      // The simulated amplifier's maps: scales depend on the axis (rated torque, encoder).
      for (const std::string& name : names) {
        if (name != "pan" && name != "tilt") {
          throw ConfigError("servo_drive: axis '" + name +
                            "' has no default register map (only pan and tilt do): set "
                            "register_map");
        }
        const bool pan = name == "pan";
        const AxisPlant plant(pan ? pan_plant_config() : tilt_plant_config());
        maps.push_back(default_register_map(pan ? pan_rated_torque_nm : tilt_rated_torque_nm,
                                            plant.output_rad_per_count()));
      }
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
      DriveAxisConfig axis;
      axis.name = names[i];
      axis.unit_id = static_cast<int>(element(unit_ids, i, "unit_ids"));
      axis.registers = maps[i];
      axis.safety = safety[i];
      if (!(axis.safety.soft_lower_rad < axis.safety.soft_upper_rad)) {
        throw ConfigError("servo_drive: axis " + axis.name +
                          ": soft_lower_rad must be below "
                          "soft_upper_rad");
      }
      c.axes.push_back(axis);
    }
    const double timeout = ctx.param<double>("response_timeout_s");
    const double period_s = 1.0 / c.cycle_rate_hz;
    if (ctx.uses_sim_time()) {
      // Waiting for a reply costs wall time only: simulated time stands still meanwhile.
      c.require_timeout_within_period = false;
      c.response_timeout_s = timeout > 0 ? timeout : 1.0;
    } else {
      c.response_timeout_s =
          timeout > 0 ? timeout : 0.4 * period_s / static_cast<double>(c.axes.size());
    }
    return c;
  }

  std::string describe_link() const {
    const DriveClientConfig& c = client_->config();
    std::string axes;
    for (const DriveAxisConfig& a : c.axes) {
      axes += (axes.empty() ? "" : ", ") + a.name + " unit " + std::to_string(a.unit_id);
    }
    char rate[64];
    std::snprintf(rate, sizeof rate, " at %.0f Hz (%s), response timeout %.3g s", c.cycle_rate_hz,
                  own_thread_ ? "own thread" : "container timer", c.response_timeout_s);
    const std::string peer = c.transport == Transport::tcp
                                 ? "tcp " + c.tcp.host + ":" + std::to_string(c.tcp.port)
                                 : "rtu " + c.rtu.device;
    return peer + " [" + axes + "]" + rate;
  }

  void on_command(const msgs::avs_msgs::JointTorqueCommand& m) {
    const auto torques = runtime::as_span(m.torque_nm);
    const auto names = runtime::as_span(m.name);
    // A command that cannot be taken whole is rejected, counted (rejected_samples) and logged
    // (rate-limited); the last valid one stays until the stale-command rule zeroes it. Before,
    // a NaN became 0 N m and a short or unnamed-and-long vector was cut or padded silently.
    for (std::size_t j = 0; j < torques.size(); ++j) {
      if (!std::isfinite(torques[j])) {
        rejected_.reject("torque " + std::to_string(j) + " is not finite");
        return;
      }
    }
    if (names.empty() ? torques.size() != names_.size() : torques.size() != names.size()) {
      rejected_.reject(std::to_string(torques.size()) + " torques for " +
                       std::to_string(names.empty() ? names_.size() : names.size()) +
                       (names.empty() ? " joints (no names: one per joint, in order)" : " names"));
      return;
    }
    // Kept between commands: a 1 kHz callback allocates nothing once it has run.
    std::vector<double>& command = command_scratch_;
    command.assign(names_.size(), 0.0);
    if (names.empty()) {
      for (std::size_t i = 0; i < std::min(command.size(), torques.size()); ++i) {
        command[i] = torques[i];
      }
    } else {
      for (std::size_t j = 0; j < names.size() && j < torques.size(); ++j) {
        const std::string_view name = runtime::get_string(names[j]);
        const auto it = std::find(names_.begin(), names_.end(), name);
        if (it == names_.end()) {
          if (!warned_unknown_joint_) log().warn("torque command for unknown joint '", name, "'");
          warned_unknown_joint_ = true;
          continue;
        }
        command[static_cast<std::size_t>(it - names_.begin())] = torques[j];
      }
    }
    const double arrival_s = context().now().seconds();
    const double stamp_s = runtime::from_ros_time(m.header.stamp).seconds();
    if (!client_->set_command(command, stamp_s, arrival_s)) report_refused_command(arrival_s);
  }

  /// Refused commands are counted by the client (and on /diagnostics); the log gets at most
  /// one line per second of the container clock, so a sender stuck ahead cannot flood it.
  void report_refused_command(double now_s) {
    if (now_s - last_refusal_log_s_ < 1.0) return;
    const CommandStatistics s = client_->command_statistics();
    if (s.future_stamped == future_stamped_logged_) return;  // older than activation: expected
    last_refusal_log_s_ = now_s;
    future_stamped_logged_ = s.future_stamped;
    log().warn("torque command rejected: stamped ", s.last_future_ahead_s,
               " s after its arrival (tolerance ",
               context().parameters().get<double>("command_future_tolerance_s"),
               " s; sender clock ahead?); ", s.future_stamped, " rejected so far");
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    const LinkStatistics l = client_->statistics();
    const CommandStatistics c = client_->command_statistics();
    return {rejected_.diagnostic(),
            {"commands_accepted", std::to_string(c.accepted)},
            {"commands_future_stamped", std::to_string(c.future_stamped)},
            {"commands_before_activation", std::to_string(c.before_activation)},
            {"exchanges", std::to_string(l.exchanges)},
            {"timeouts", std::to_string(l.timeouts)},
            {"missed_cycles", std::to_string(l.missed_cycles)},
            {"late_replies", std::to_string(l.late_replies)},
            {"exceptions", std::to_string(l.exceptions)},
            {"stale_replies", std::to_string(l.stale_replies)},
            {"bad_replies", std::to_string(l.bad_replies)},
            {"errors", std::to_string(l.errors)},
            {"reconnects", std::to_string(l.reconnects)}};
  }

  /// The live parameters (command rules, e-stop action, automatic fault reset, soft-limit
  /// rules, status rate) take effect from the next drive cycle (DriveClient::retune); a refusal
  /// (soft_lower_rad not below soft_upper_rad) changes nothing.
  void on_parameters_changed(const runtime::ParameterValues& values,
                             const std::vector<std::string>& /*changed*/) override {
    const DriveClientConfig c = params().make(values);
    DriveLiveSettings live;
    live.command_freshness = c.command_freshness;
    live.estop_action = c.estop_action;
    live.auto_fault_reset = c.auto_fault_reset;
    live.safety = safety_of(values, names_.size());
    client_->retune(live);
    cycles_per_status_ = status_cycles(values);
  }

  std::int64_t status_cycles(const runtime::ParameterValues& values) const {
    const double cycle_rate_hz = 1e9 / static_cast<double>(period_.count());
    return std::max<std::int64_t>(
        1, std::llround(cycle_rate_hz / values.get<double>("status_rate_hz")));
  }

  void on_estop(bool active) {
    if (active != estop_.load()) log().warn(active ? "e-stop engaged" : "e-stop released");
    estop_ = active;
    client_->set_estop(active, context().now().seconds());
  }

  void on_fault_reset() {
    log().info("fault reset requested");
    client_->request_fault_reset();
  }

  void thread_loop() {
    if (rt_priority_ > 0) {
      sched_param param{};
      param.sched_priority = rt_priority_;
      const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
      if (rc != 0) {
        log().warn("SCHED_FIFO priority ", rt_priority_, " refused (", std::strerror(rc),
                   "): running with normal scheduling");
      }
    }
    using Clock = std::chrono::steady_clock;
    auto next = Clock::now() + period_;
    while (!stop_) {
      std::this_thread::sleep_until(next);
      try {
        run_cycle();
      } catch (const std::exception& e) {
        log().error(e.what(), ": cyclic thread stopped, torque off");
        return;
      }
      next += period_;
      const auto now = Clock::now();
      if (now > next + 10 * period_) next = now + period_;  // no burst after a long stall
    }
  }

  void stop_thread() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

  void run_cycle() {
    const runtime::Time now = context().now();
    client_->cycle(now.seconds(), cycle_result_);  // reuses its memory: no allocation
    const CycleResult& r = cycle_result_;
    if (!client_->fatal_error().empty()) throw ConfigError(client_->fatal_error());
    ++cycles_;
    const bool fault = r.link_fault || !r.fault_message.empty();
    if (r.link_fault) {
      ++link_fault_cycles_;
      if (first_link_fault_s_ < 0) first_link_fault_s_ = now.seconds();
      last_link_fault_s_ = now.seconds();
    }
    if (fault && r.fault_message != last_message_) {
      log().warn(r.fault_message.empty() ? "fault" : r.fault_message);
      if (first_fault_message_.empty()) first_fault_message_ = r.fault_message;
    }
    if (!fault && last_fault_) log().info("link and drives healthy again");
    if (!fault && !r.link_ok) report_missed_cycle(now.seconds());
    last_message_ = fault ? r.fault_message : std::string();
    const bool changed = cycles_ == 1 || fault != last_fault_ || r.link_ok != last_link_ok_;
    last_fault_ = fault;
    last_link_ok_ = r.link_ok;

    if (r.link_ok) publish_joint_states(now, r);
    if (changed || cycles_ % cycles_per_status_ == 0) publish_status(now, r);
    if (!report_dir_.empty()) record(now, r, fault);
  }

  /// A reply later than the response timeout, once: counted (missed_cycles on /diagnostics)
  /// and logged at most once a second of the graph's clock with the count since the last line.
  void report_missed_cycle(double now_s) {
    ++missed_since_log_;
    if (now_s - last_missed_log_s_ < 1.0) return;
    log().warn(missed_since_log_,
               " axis repl(ies) later than the response timeout since the last report: each a "
               "missed cycle (the drive keeps the last torque for that period); a second in a "
               "row on an axis is a link fault (missed_cycles on /diagnostics)");
    missed_since_log_ = 0;
    last_missed_log_s_ = now_s;
  }

  void publish_joint_states(runtime::Time now, const CycleResult& r) {
    auto msg = joint_states_.loan();  // every field set below
    runtime::to_ros_time(now, msg->header.stamp);
    runtime::set_string(msg->header.frame_id, "head");
    const auto n = static_cast<std::uint32_t>(r.axes.size());
    runtime::resize_sequence(msg->name, n);
    runtime::resize_sequence(msg->position, n);
    runtime::resize_sequence(msg->velocity, n);
    runtime::resize_sequence(msg->effort, n);
    for (std::uint32_t i = 0; i < n; ++i) {
      runtime::set_string(msg->name._buffer[i], names_[i]);
      msg->position._buffer[i] = r.axes[i].q_rad;
      msg->velocity._buffer[i] = r.axes[i].qd_rad_s;
      msg->effort._buffer[i] = r.axes[i].torque_actual_nm;
    }
    joint_states_.publish(std::move(msg));
  }

  void publish_status(runtime::Time now, const CycleResult& r) {
    const LinkStatistics s = client_->statistics();
    auto msg = drive_status_.loan();  // every field set below (frame_id stays empty)
    runtime::to_ros_time(now, msg->header.stamp);
    const auto n = static_cast<std::uint32_t>(r.axes.size());
    runtime::resize_sequence(msg->axes, n);
    for (std::uint32_t i = 0; i < n; ++i) {
      auto& a = msg->axes._buffer[i];
      const AxisFeedback& fb = r.axes[i];
      runtime::set_string(a.name, names_[i]);
      a.statusword = fb.statusword;
      a.controlword = fb.controlword;
      a.state = static_cast<std::uint8_t>(fb.state);
      a.fault = r.link_fault || fb.fault_latched || fb.state == DriveState::fault ||
                fb.state == DriveState::fault_reaction_active;
      a.error_code = fb.error_code;
      a.commanded_torque_nm = fb.commanded_torque_nm;
    }
    msg->link_ok = r.link_ok;
    msg->exchanges = s.exchanges;
    msg->timeouts = s.timeouts;
    msg->errors = s.errors + s.exceptions + s.stale_replies + s.bad_replies;
    msg->reconnects = s.reconnects;
    msg->rtt_us_p50 = std::isnan(s.rtt_us_p50) ? 0.0 : s.rtt_us_p50;
    msg->rtt_us_p99 = std::isnan(s.rtt_us_p99) ? 0.0 : s.rtt_us_p99;
    drive_status_.publish(std::move(msg));
  }

  // Test report: one CSV row per cycle (simulated-time runs are reproducible to the bit).
  void record(runtime::Time now, const CycleResult& r, bool fault) {
    char line[160];
    std::snprintf(line, sizeof line, "%.6f,%d,%d,%d", now.seconds(), r.link_ok ? 1 : 0,
                  fault ? 1 : 0, estop_.load() ? 1 : 0);
    csv_ += line;
    for (const AxisFeedback& a : r.axes) {
      std::snprintf(line, sizeof line, ",%.9g,%.9g,%.9g,%d,%d", a.commanded_torque_nm, a.q_rad,
                    a.qd_rad_s, static_cast<int>(a.state), a.error_code);
      csv_ += line;
    }
    csv_ += '\n';
  }

  void write_report(const LinkStatistics& s) {
    if (report_dir_.empty()) return;
    const std::string base = report_dir_ + "/" + context().name();
    std::ofstream csv(base + ".csv");
    csv << "t_s,link_ok,fault,estop";
    for (const std::string& n : names_) {
      csv << ',' << n << "_cmd_nm," << n << "_q_rad," << n << "_qd_rad_s," << n << "_state," << n
          << "_error_code";
    }
    csv << '\n' << csv_;
    std::ofstream yaml(base + ".yaml");
    yaml << "cycles: " << cycles_ << "\nlink_fault_cycles: " << link_fault_cycles_
         << "\nfirst_link_fault_s: " << first_link_fault_s_
         << "\nlast_link_fault_s: " << last_link_fault_s_ << "\nexchanges: " << s.exchanges
         << "\ntimeouts: " << s.timeouts << "\nmissed_cycles: " << s.missed_cycles
         << "\nlate_replies: " << s.late_replies << "\nexceptions: " << s.exceptions
         << "\nstale_replies: " << s.stale_replies << "\nbad_replies: " << s.bad_replies
         << "\nerrors: " << s.errors << "\nreconnects: " << s.reconnects
         << "\nconnect_failures: " << s.connect_failures
         << "\ncommands_future_stamped: " << client_->command_statistics().future_stamped
         << "\nrejected_commands: " << rejected_.count() << "\nfirst_fault_message: \""
         << first_fault_message_ << "\"\n";
    if (!csv || !yaml) log().error("cannot write the report to ", base, ".{csv,yaml}");
  }

  runtime::Publisher<msgs::sensor_msgs::JointState> joint_states_;
  runtime::Publisher<msgs::avs_msgs::DriveStatus> drive_status_;
  bool own_thread_;
  int rt_priority_;
  std::string report_dir_;
  std::vector<std::string> names_;
  std::unique_ptr<DriveClient> client_;
  CycleResult cycle_result_;             ///< run_cycle()'s, reused every cycle
  std::vector<double> command_scratch_;  ///< on_command()'s, reused every command
  std::int64_t missed_since_log_ = 0;
  double last_missed_log_s_ = -1e300;
  runtime::Duration period_{1'000'000};
  std::atomic<std::int64_t> cycles_per_status_ = 100;  ///< set live, read by the cycle
  runtime::TimerId timer_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> estop_{false};
  bool warned_unknown_joint_ = false;
  runtime::SampleRejections rejected_;  ///< /head/torque_command samples not taken
  double last_refusal_log_s_ = -1e300;  ///< subscription callback only
  std::uint64_t future_stamped_logged_ = 0;

  // Cycle bookkeeping (cycle thread / timer only).
  std::int64_t cycles_ = 0;
  std::int64_t link_fault_cycles_ = 0;
  double first_link_fault_s_ = -1;
  double last_link_fault_s_ = -1;
  bool last_fault_ = false;
  bool last_link_ok_ = false;
  std::string last_message_;
  std::string first_fault_message_;
  std::string csv_;
};

AVS_REGISTER_COMPONENT(ServoDrive);

}  // namespace avs::servo
