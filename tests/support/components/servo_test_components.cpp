// Small components for the servo graph tests (tests/integration_servo/):
//   test_torque_step   - publishes a torque command schedule (zero, a step, zero), an
//                        optional e-stop window and fault reset on the container clock,
//                        optionally stamped ahead of the clock, and malformed commands
//                        (a NaN torque, fewer torques than names) in a window;
//   test_head_recorder - records /sim/head_state and /head/joint_states to CSV files
//                        <report_dir>/<name>_sim.csv and <name>_joints.csv on deactivate.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "avs/runtime/component.hpp"

namespace avs::servo {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class TestTorqueStep final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_1;
    keep_last_1.depth = 1;
    runtime::QosProfile estop_qos = keep_last_1;
    estop_qos.durability = runtime::Durability::transient_local;
    return {.type = "test_torque_step",
            .description =
                "tests: publishes /head/torque_command (torque_nm inside "
                "[step_at_s, step_until_s), else 0) and an e-stop window",
            .parameters =
                {ParamSpec::real("rate_hz", 1000.0, 0.1, 100000.0, "Hz", "command rate"),
                 ParamSpec::string("joint_names", "pan,tilt",
                                   "comma-separated joint names (at most 2)"),
                 ParamSpec::real_list("torque_nm", {0.5, 0.0}, "N m",
                                      "motor torque per joint during the step"),
                 ParamSpec::real("step_at_s", 0.1, 0.0, std::nullopt, "s",
                                 "step start (container clock)")
                     .live(),
                 ParamSpec::real("step_until_s", 0.12, 0.0, std::nullopt, "s", "step end").live(),
                 ParamSpec::real("estop_at_s", -1.0, -1.0, std::nullopt, "s",
                                 "publish e-stop true at this time (-1 = never)"),
                 ParamSpec::real("estop_release_s", -1.0, -1.0, std::nullopt, "s",
                                 "publish e-stop false at this time (-1 = never)"),
                 ParamSpec::real("fault_reset_at_s", -1.0, -1.0, std::nullopt, "s",
                                 "publish one /head/fault_reset at this time (-1 = never)"),
                 ParamSpec::real("stamp_offset_s", 0.0, -1e6, 1e6, "s",
                                 "stamp the commands this much after the clock (a "
                                 "sender clock ahead, if positive)"),
                 ParamSpec::real("bad_from_s", -1.0, -1.0, std::nullopt, "s",
                                 "from this time (-1 = never) until bad_until_s, "
                                 "malformed commands: a NaN torque, then one torque "
                                 "for two names, in turn"),
                 ParamSpec::real("bad_until_s", -1.0, -1.0, std::nullopt, "s",
                                 "end of the malformed commands")},
            .publishes = {runtime::port<msgs::avs_msgs::JointTorqueCommand>(
                              "torque_command", "/head/torque_command", keep_last_1),
                          runtime::port<msgs::std_msgs::Bool>("estop", "/head/estop", estop_qos),
                          runtime::port<msgs::std_msgs::Empty>("fault_reset", "/head/fault_reset")},
            .subscribes = {}};
  }

  explicit TestTorqueStep(ComponentContext& ctx)
      : Component(ctx),
        command_(ctx.publisher<msgs::avs_msgs::JointTorqueCommand>("torque_command")),
        estop_(ctx.publisher<msgs::std_msgs::Bool>("estop")),
        fault_reset_(ctx.publisher<msgs::std_msgs::Empty>("fault_reset")),
        period_(static_cast<std::int64_t>(1e9 / ctx.param<double>("rate_hz"))),
        torque_(ctx.param<std::vector<double>>("torque_nm")),
        step_at_s_(ctx.param<double>("step_at_s")),
        step_until_s_(ctx.param<double>("step_until_s")),
        estop_at_s_(ctx.param<double>("estop_at_s")),
        estop_release_s_(ctx.param<double>("estop_release_s")),
        fault_reset_at_s_(ctx.param<double>("fault_reset_at_s")),
        stamp_offset_(std::llround(ctx.param<double>("stamp_offset_s") * 1e9)),
        bad_from_s_(ctx.param<double>("bad_from_s")),
        bad_until_s_(ctx.param<double>("bad_until_s")) {
    const std::string names = ctx.param<std::string>("joint_names");
    for (std::size_t start = 0; start <= names.size();) {
      const std::size_t comma = std::min(names.find(',', start), names.size());
      if (comma > start) names_.push_back(names.substr(start, comma - start));
      start = comma + 1;
    }
    if (names_.size() != torque_.size()) {
      throw std::invalid_argument("joint_names has " + std::to_string(names_.size()) +
                                  " names but torque_nm " + std::to_string(torque_.size()) +
                                  " values");
    }
  }

  void on_activate() override {
    context().create_timer(period_, [this] { tick(); });
  }

  /// A test starts the step when it wants (`avs param set source step_at_s 0`), e.g. after a
  /// live change of the drive's parameters: the order is then certain in lockstep too.
  void on_parameters_changed(const runtime::ParameterValues& values,
                             const std::vector<std::string>& /*changed*/) override {
    step_at_s_ = values.get<double>("step_at_s");
    step_until_s_ = values.get<double>("step_until_s");
  }

 private:
  void tick() {
    const runtime::Time now = context().now();
    const double t = now.seconds();
    if (estop_at_s_ >= 0 && !estop_sent_ && t >= estop_at_s_) {
      publish_estop(true);
      estop_sent_ = true;
    }
    if (estop_release_s_ >= 0 && !release_sent_ && t >= estop_release_s_) {
      publish_estop(false);
      release_sent_ = true;
    }
    if (fault_reset_at_s_ >= 0 && !reset_sent_ && t >= fault_reset_at_s_) {
      fault_reset_.publish(runtime::make_sample<msgs::std_msgs::Empty>());
      reset_sent_ = true;
    }
    const bool on = t >= step_at_s_ && t < step_until_s_;
    auto msg = runtime::make_sample<msgs::avs_msgs::JointTorqueCommand>();
    runtime::to_ros_time(now + stamp_offset_, msg->header.stamp);
    const auto n = static_cast<std::uint32_t>(names_.size());
    runtime::resize_sequence(msg->name, n);
    runtime::resize_sequence(msg->torque_nm, n);
    for (std::uint32_t i = 0; i < n; ++i) {
      runtime::set_string(msg->name._buffer[i], names_[i]);
      msg->torque_nm._buffer[i] = on ? torque_[i] : 0.0;
    }
    if (bad_from_s_ >= 0 && t >= bad_from_s_ && t < bad_until_s_) {
      if (bad_sent_++ % 2 == 0) {
        msg->torque_nm._buffer[0] = std::numeric_limits<double>::quiet_NaN();
      } else {
        runtime::resize_sequence(msg->torque_nm, n > 0 ? n - 1 : 0);  // fewer torques than names
      }
    }
    command_.publish(std::move(msg));
  }

  void publish_estop(bool active) {
    auto msg = runtime::make_sample<msgs::std_msgs::Bool>();
    msg->data = active;
    estop_.publish(std::move(msg));
  }

  runtime::Publisher<msgs::avs_msgs::JointTorqueCommand> command_;
  runtime::Publisher<msgs::std_msgs::Bool> estop_;
  runtime::Publisher<msgs::std_msgs::Empty> fault_reset_;
  runtime::Duration period_;
  std::vector<double> torque_;
  std::vector<std::string> names_;
  double step_at_s_;
  double step_until_s_;
  double estop_at_s_;
  double estop_release_s_;
  double fault_reset_at_s_;
  runtime::Duration stamp_offset_;
  double bad_from_s_;
  double bad_until_s_;
  std::uint64_t bad_sent_ = 0;
  bool estop_sent_ = false;
  bool release_sent_ = false;
  bool reset_sent_ = false;
};

class TestHeadRecorder final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {
        .type = "test_head_recorder",
        .description = "tests: records /sim/head_state and /head/joint_states to CSV",
        .parameters = {ParamSpec::string("report_dir", "",
                                         "folder for <name>_sim.csv and <name>_joints.csv "
                                         "(written on deactivate); empty = none")},
        .publishes = {},
        .subscribes = {
            runtime::port<msgs::sensor_msgs::JointState>("head_state", "/sim/head_state"),
            runtime::port<msgs::sensor_msgs::JointState>("joint_states", "/head/joint_states")}};
  }

  explicit TestHeadRecorder(ComponentContext& ctx)
      : Component(ctx), report_dir_(ctx.param<std::string>("report_dir")) {
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "head_state",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { append(sim_, *m); });
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { append(joints_, *m); });
  }

  void on_deactivate() override {
    if (report_dir_.empty()) return;
    write(report_dir_ + "/" + context().name() + "_sim.csv", sim_);
    write(report_dir_ + "/" + context().name() + "_joints.csv", joints_);
  }

 private:
  static void append(std::string& out, const msgs::sensor_msgs::JointState& m) {
    char text[96];
    std::snprintf(text, sizeof text, "%.6f", runtime::from_ros_time(m.header.stamp).seconds());
    out += text;
    for (std::uint32_t i = 0; i < m.position._length; ++i) {
      const double qd = i < m.velocity._length ? m.velocity._buffer[i] : 0.0;
      const double effort = i < m.effort._length ? m.effort._buffer[i] : 0.0;
      std::snprintf(text, sizeof text, ",%.12g,%.12g,%.12g", m.position._buffer[i], qd, effort);
      out += text;
    }
    out += '\n';
  }

  void write(const std::string& file, const std::string& rows) {
    std::ofstream out(file);
    out << "t_s,pan_q_rad,pan_qd_rad_s,pan_effort_nm,tilt_q_rad,tilt_qd_rad_s,tilt_effort_nm\n"
        << rows;
    if (!out) log().error("cannot write ", file);
  }

  std::string report_dir_;
  std::string sim_;
  std::string joints_;
};

AVS_REGISTER_COMPONENT(TestTorqueStep);
AVS_REGISTER_COMPONENT(TestHeadRecorder);

}  // namespace avs::servo
