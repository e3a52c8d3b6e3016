// tracking: the visual servo of the paper's section 5 as a component. Per depth image
// (/depth/image, 32FC1 metres, NaN invalid): moments and centroid of the depth window
// phi_l < h_c < phi_h (Eqs. 7-9) -> /target; the tracker's states around the servo law
// tau = Kp J^-1 (m_d - m_g) - Kv q' (Eq. 16, image Jacobian of Eq. 15, full or simplified)
// with the latest /head/joint_states -> /head/torque_command. `enabled: false` is the paper's
// "no tracking" run: the head holds its pose (joint PD) whatever the image shows. The camera
// model (focal lengths, principal point, distortion) comes from /depth/camera_info, the decoder's
// calibration in force: tracking keeps none of its own.
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>

#include "avs/msg/camera_info.hpp"
#include "avs/msg/camera_input.hpp"
#include "avs/msg/convert.hpp"
#include "avs/msg/depth_image.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/runtime/rejections.hpp"
#include "avs/tracking/depth_gate.hpp"
#include "avs/tracking/tracker.hpp"

namespace avs::tracking {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class TrackingComponent final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_1;
    keep_last_1.depth = 1;
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {
        .type = "tracking",
        .description =
            "target moments from the depth window (Eqs. 7-9) and the visual servo "
            "law (Eqs. 15-16): /depth/image + /depth/camera_info + /head/joint_states -> "
            "/target, /head/torque_command",
        .parameters = params().specs_with(
            {ParamSpec::boolean("enabled", true,
                                "false: never track, hold the head's pose (the no-tracking run)")
                 .live(),
             ParamSpec::string("joint_names", "pan,tilt",
                               "names of q1 and q2 in /head/joint_states and the command"),
             ParamSpec::string("report_dir", "",
                               "tests: write <name>.csv (one row per image) on deactivate")}),
        .publishes = {runtime::port<msgs::avs_msgs::TargetObservation>("target", "/target"),
                      runtime::port<msgs::avs_msgs::JointTorqueCommand>(
                          "torque_command", "/head/torque_command", keep_last_1),
                      runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing")},
        .subscribes = {runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image",
                                                               keep_last_4),
                       runtime::port<msgs::sensor_msgs::CameraInfo>(
                           "camera_info", "/depth/camera_info", msg::camera_info_qos()),
                       runtime::port<msgs::sensor_msgs::JointState>("joint_states",
                                                                    "/head/joint_states")},
        .default_mismatches = [] { return params().default_mismatches(); }};
  }

  /// The cores' configurations behind the parameters (their defaults are the parameters').
  struct CoreConfig {
    TrackerConfig tracker;
    MomentsConfig moments;
    DepthGateConfig gate;
  };

  /// Parameters bound to the core configs (Eqs. 8, 15, 16 and the tracking states).
  static const runtime::ConfigParams<CoreConfig>& params() {
    static const auto p =
        runtime::ConfigParams<CoreConfig>()
            .real("depth_min_m", AVS_FIELD(moments.depth_min_m), 0.0, 100.0, "m", "phi_l of Eq. 8")
            .live()
            .real("depth_max_m", AVS_FIELD(moments.depth_max_m), 0.0, 100.0, "m", "phi_h of Eq. 8")
            .live()
            .real("min_area_px", AVS_FIELD(moments.min_area_px), 1.0, 1e7, "px",
                  "m00 below this: no target")
            .live()
            .real("depth_gate_m", AVS_FIELD(gate.half_width_m), 0.0, 10.0, "m",
                  "once a target is seen, Eq. 8's window narrows to its mean depth +- this, so "
                  "what passes in front of it is left out (0: off, the paper's fixed window)")
            .live()
            .integer("depth_gate_release_frames", AVS_FIELD(gate.release_frames), 1, 10000000, "",
                     "depth images without a target before the gate opens to Eq. 8's window")
            .live()
            .real("depth_gate_max_step_m", AVS_FIELD(gate.max_step_m), 1e-6, 10.0, "m",
                  "with the gate: its centre follows the target by at most this per image")
            .live()
            .real("depth_gate_region_scale", AVS_FIELD(gate.region_scale), 0.0, 1000.0, "",
                  "with the gate: only pixels within this x sqrt(m00) (plus "
                  "depth_gate_region_margin_px) of the last centroid can be target")
            .live()
            .integer("depth_gate_region_margin_px", AVS_FIELD(gate.region_margin_px), 0, 100000,
                     "px", "with the gate: added to the region's half-size")
            .live()
            .real("depth_gate_min_area_share", AVS_FIELD(gate.min_area_share), 0.0, 1.0, "",
                  "with the gate: a mask below this share of the target's running area is no "
                  "target (it is hidden)")
            .live()
            .choice("jacobian", AVS_FIELD(tracker.law.jacobian),
                    std::vector<std::pair<std::string, JacobianForm>>{
                        {"full", JacobianForm::full}, {"simplified", JacobianForm::simplified}},
                    "image Jacobian of Eq. 15")
            .real("a_m", AVS_FIELD(tracker.law.a_m), -1.0, 1.0, "m",
                  "Figure 3: tilt axis to camera centre along X_c (full Jacobian)")
            .vector("kp_nm_per_rad", AVS_FIELD(tracker.law.kp_nm_per_rad), "N m/rad",
                    "K_p (pan, tilt); tuned on servo_tracking_loop.yaml", 0.0, 1000.0)
            .live()
            .vector("kv_nm_s_per_rad", AVS_FIELD(tracker.law.kv_nm_s_per_rad), "N m s/rad",
                    "K_v (pan, tilt); tuned on servo_tracking_loop.yaml", 0.0, 1000.0)
            .live()
            .vector("m_d_px", AVS_FIELD(tracker.law.m_d_px), "px",
                    "desired image position relative to the principal point", -100000.0, 100000.0)
            .live()
            .vector("max_torque_nm", AVS_FIELD(tracker.law.max_torque_nm), "N m",
                    "motor torque limit per axis (Table 3)", 0.0, 100.0)
            .live()
            .real("min_cos_q2", AVS_FIELD(tracker.law.min_cos_q2), 0.001, 1.0, "",
                  "|cos q2| floor that keeps J invertible")
            .integer("frames_to_track", AVS_FIELD(tracker.frames_to_track), 1, 100000, "",
                     "consecutive frames with a target before tracking")
            .live()
            .integer("frames_to_idle", AVS_FIELD(tracker.frames_to_idle), 0, 10000000, "",
                     "frames without target in 'lost' before 'idle'")
            .live()
            .choice("idle", AVS_FIELD(tracker.idle),
                    std::vector<std::pair<std::string, IdleBehaviour>>{
                        {"hold", IdleBehaviour::hold}, {"return_home", IdleBehaviour::return_home}},
                    "idle behaviour")
            .live()
            .vector("home_q_rad", AVS_FIELD(tracker.home_q_rad), "rad", "home pose (return_home)",
                    -7.0, 7.0)
            .live()
            .vector("hold_kp_nm_per_rad", AVS_FIELD(tracker.hold_kp_nm_per_rad), "N m/rad",
                    "joint PD for hold / home", 0.0, 1000.0)
            .live()
            .vector("hold_kv_nm_s_per_rad", AVS_FIELD(tracker.hold_kv_nm_s_per_rad), "N m s/rad",
                    "joint PD for hold / home", 0.0, 1000.0)
            .live();
    return p;
  }

  explicit TrackingComponent(ComponentContext& ctx)
      : Component(ctx),
        target_(ctx.publisher<msgs::avs_msgs::TargetObservation>("target")),
        command_(ctx.publisher<msgs::avs_msgs::JointTorqueCommand>("torque_command")),
        timing_(ctx.publisher<msgs::avs_msgs::StageTiming>("timing")),
        core_(params().make(ctx.parameters())),
        tracker_(core_.tracker),
        gate_(core_.gate),
        enabled_(ctx.param<bool>("enabled")),
        report_dir_(ctx.param<std::string>("report_dir")),
        rejected_(ctx.log(), "input") {
    moments_ = core_.moments;
    if (!(moments_.depth_min_m < moments_.depth_max_m)) {
      throw std::invalid_argument("depth_min_m must be below depth_max_m");
    }
    const auto names =
        msg::parse_name_list(ctx.param<std::string>("joint_names"), 2, "joint_names");
    joint_names_ = {names[0], names[1]};
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { on_joints(*m); });
    ctx.subscribe<msgs::sensor_msgs::CameraInfo>(
        "camera_info",
        [this](runtime::SamplePtr<msgs::sensor_msgs::CameraInfo> m) { on_camera_info(*m); });
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth(*m); });
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    return {rejected_.diagnostic()};
  }

  /// The live gains, limits, depth window, state thresholds and `enabled` take effect from the
  /// next depth image on; the tracking state stays.
  void on_parameters_changed(const runtime::ParameterValues& values,
                             const std::vector<std::string>& /*changed*/) override {
    const CoreConfig core = params().make(values);
    if (!(core.moments.depth_min_m < core.moments.depth_max_m)) {
      throw std::invalid_argument("depth_min_m must be below depth_max_m");
    }
    tracker_.retune(core.tracker);
    gate_.retune(core.gate);
    moments_ = core.moments;
    enabled_ = values.get<bool>("enabled");
  }

  void on_deactivate() override {
    log().info(images_, " depth images, ", frames_with_target_, " with a target, state ",
               to_string(tracker_.state()));
    if (report_dir_.empty()) return;
    const std::string file = report_dir_ + "/" + context().name() + ".csv";
    std::ofstream out(file);
    out << "t_s,valid,m00,centroid_u_px,centroid_v_px,mean_depth_m,state,pan_torque_nm,"
           "tilt_torque_nm\n"
        << csv_;
    if (!out) log().error("cannot write ", file);
  }

 private:
  void on_joints(const msgs::sensor_msgs::JointState& m) {
    for (int axis = 0; axis < 2; ++axis) {
      const std::string& name = joint_names_[static_cast<std::size_t>(axis)];
      const auto joint = msg::find_joint(m, name);
      if (!joint) continue;
      if (!std::isfinite(joint->position) || !std::isfinite(joint->velocity)) {
        // A NaN here would become a NaN torque command: keep the previous joint state.
        rejected_.reject("joint state '" + name + "' not finite (position " +
                         std::to_string(joint->position) + ", velocity " +
                         std::to_string(joint->velocity) + ")");
        continue;
      }
      joints_.q_rad[axis] = joint->position;
      joints_.qd_rad_s[axis] = joint->velocity;
      have_axis_[axis] = true;
    }
  }

  void on_camera_info(const msgs::sensor_msgs::CameraInfo& m) {
    if (!camera_.update(m)) return;
    const geometry::CameraModel& c = *camera_.model();
    tracker_.set_focal_lengths_px(c.fx_px, c.fy_px);  // Eq. 15's f
  }

  void on_depth(const msgs::sensor_msgs::Image& image) {
    std::string why;
    const auto layout = msg::depth_view(image, &why);
    if (!layout) {
      rejected_.reject(why);
      return;
    }
    if (!camera_.accepts_image(layout->width_px, layout->height_px)) return;
    ++images_;
    const auto started = std::chrono::steady_clock::now();
    const geometry::DepthView& view = *layout;
    // Eqs. 7-9 in Eq. 8's window, narrowed to the target's depth once one is seen (DepthGate).
    TargetObservation obs = measure_target(view, *camera_.model(), gate_.window(moments_));
    obs.present = gate_.observe(obs);  // a remnant of a hidden target is no target
    if (obs.present) ++frames_with_target_;
    publish_target(image, obs);

    Eigen::Vector2d torque = Eigen::Vector2d::Zero();
    TrackingState state = TrackingState::idle;
    if (have_axis_[0] && have_axis_[1]) {
      // Disabled: the tracker never sees a target, so it stays idle and holds the pose.
      TargetObservation input = obs;
      if (!enabled_) input.present = false;
      const TrackerResult result = tracker_.update(input, joints_);
      torque = result.torque_nm;
      state = result.state;
    } else if (!warned_no_joints_) {
      log().warn("no /head/joint_states for both joints yet: zero torque");
      warned_no_joints_ = true;
    }
    publish_command(torque);
    publish_timing(image, started);
    if (!report_dir_.empty()) {
      char line[256];
      std::snprintf(line, sizeof line, "%.6f,%d,%.9g,%.9g,%.9g,%.9g,%d,%.9g,%.9g\n",
                    runtime::from_ros_time(image.header.stamp).seconds(), obs.present ? 1 : 0,
                    obs.m00, obs.centroid_u_px, obs.centroid_v_px, obs.mean_depth_m,
                    static_cast<int>(state), torque[0], torque[1]);
      csv_ += line;
    }
  }

  void publish_target(const msgs::sensor_msgs::Image& image, const TargetObservation& obs) {
    auto msg = target_.loan();  // every field set below
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->header.frame_id, runtime::get_string(image.header.frame_id));
    msg->m00 = obs.m00;
    msg->m10 = obs.m10;
    msg->m01 = obs.m01;
    msg->centroid_x_px = obs.centroid_u_px;
    msg->centroid_y_px = obs.centroid_v_px;
    msg->mean_depth_m = obs.mean_depth_m;
    msg->valid = obs.present;
    target_.publish(std::move(msg));
  }

  /// Wall-clock time of moments + servo law for this image (the "tracking" stage of reports).
  void publish_timing(const msgs::sensor_msgs::Image& image,
                      std::chrono::steady_clock::time_point started) {
    auto msg = timing_.loan();  // every field set below (frame_id stays empty)
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->stage, "tracking");
    msg->processing_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count();
    timing_.publish(std::move(msg));
  }

  void publish_command(const Eigen::Vector2d& torque) {
    auto msg = command_.loan();  // every field set below
    // Stamped when computed: servo_drive's command timeout measures from here.
    runtime::to_ros_time(context().now(), msg->header.stamp);
    runtime::resize_sequence(msg->name, 2);
    runtime::resize_sequence(msg->torque_nm, 2);
    for (std::uint32_t i = 0; i < 2; ++i) {
      runtime::set_string(msg->name._buffer[i], joint_names_[i]);
      msg->torque_nm._buffer[i] = torque[static_cast<int>(i)];
    }
    command_.publish(std::move(msg));
  }

  runtime::Publisher<msgs::avs_msgs::TargetObservation> target_;
  runtime::Publisher<msgs::avs_msgs::JointTorqueCommand> command_;
  runtime::Publisher<msgs::avs_msgs::StageTiming> timing_;
  CoreConfig core_;
  Tracker tracker_;
  DepthGate gate_;
  bool enabled_;
  std::string report_dir_;
  runtime::SampleRejections rejected_;
  msg::CameraInput camera_{log(), rejected_};  ///< from /depth/camera_info
  MomentsConfig moments_;
  std::array<std::string, 2> joint_names_;
  JointState joints_;
  bool have_axis_[2] = {false, false};
  bool warned_no_joints_ = false;
  std::uint64_t images_ = 0;
  std::uint64_t frames_with_target_ = 0;
  std::string csv_;
};

AVS_REGISTER_COMPONENT(TrackingComponent);

}  // namespace avs::tracking
