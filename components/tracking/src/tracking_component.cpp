// tracking: the visual servo of the paper's section 5 as a component. Per depth image
// (/depth/image, 32FC1 metres, NaN invalid): moments and centroid of the depth window
// phi_l < h_c < phi_h (Eqs. 7-9) -> /target; the tracker's states around the servo law
// tau = Kp J^-1 (m_d - m_g) - Kv q' (Eq. 16, image Jacobian of Eq. 15, full or simplified)
// with the latest /head/joint_states -> /head/torque_command. `enabled: false` is the paper's
// "no tracking" run: the head holds its pose (joint PD) whatever the image shows.
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>

#include "avs/runtime/component.hpp"
#include "avs/runtime/depth_image.hpp"
#include "avs/tracking/tracker.hpp"

namespace avs::tracking {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

namespace {

Eigen::Vector2d pair(const std::vector<double>& v, const std::string& name) {
  if (v.size() != 2) {
    throw std::invalid_argument("parameter '" + name + "' needs 2 values (pan, tilt), got " +
                                std::to_string(v.size()));
  }
  return {v[0], v[1]};
}

}  // namespace

class TrackingComponent final : public runtime::Component {
 public:
  /// Camera defaults: the paper's sensor as avs::decode::default_sensor_geometry() models it
  /// (512 x 512, f = 256 / tan(22.15 deg) = 628.8 px, principal point at the centre).
  static constexpr double default_f_px = 628.8;
  static constexpr double default_c_px = 255.5;

  static ComponentSpec spec() {
    runtime::QosProfile keep_last_1;
    keep_last_1.depth = 1;
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {
        .type = "tracking",
        .description =
            "target moments from the depth window (Eqs. 7-9) and the visual servo "
            "law (Eqs. 15-16): /depth/image + /head/joint_states -> /target, "
            "/head/torque_command",
        .parameters =
            {ParamSpec::boolean("enabled", true,
                                "false: never track, hold the head's pose (the no-tracking run)"),
             ParamSpec::real("fx_px", default_f_px, 1.0, 1e5, "px", "focal length along x"),
             ParamSpec::real("fy_px", default_f_px, 1.0, 1e5, "px", "focal length along y"),
             ParamSpec::real("cx_px", default_c_px, -1e4, 1e4, "px", "principal point x"),
             ParamSpec::real("cy_px", default_c_px, -1e4, 1e4, "px", "principal point y"),
             ParamSpec::real("depth_min_m", 0.3, 0.0, 100.0, "m", "phi_l of Eq. 8"),
             ParamSpec::real("depth_max_m", 1.5, 0.0, 100.0, "m", "phi_h of Eq. 8"),
             ParamSpec::real("min_area_px", 50.0, 1.0, 1e7, "px", "m00 below this: no target"),
             ParamSpec::string("jacobian", "simplified", "image Jacobian of Eq. 15",
                               {"full", "simplified"}),
             ParamSpec::real("a_m", 0.0, -1.0, 1.0, "m",
                             "Figure 3: tilt axis to camera centre along X_c (full Jacobian)"),
             ParamSpec::real_list("kp_nm_per_rad", {12.0, 2.0}, "N m/rad",
                                  "K_p (pan, tilt); tuned on servo_tracking_loop.yaml"),
             ParamSpec::real_list("kv_nm_s_per_rad", {0.3, 0.05}, "N m s/rad",
                                  "K_v (pan, tilt); tuned on servo_tracking_loop.yaml"),
             ParamSpec::real_list("m_d_px", {0.0, 0.0}, "px",
                                  "desired image position relative to the principal point"),
             ParamSpec::real_list("max_torque_nm", {5.73, 0.9555}, "N m",
                                  "motor torque limit per axis (Table 3)"),
             ParamSpec::real("min_cos_q2", 0.1, 0.001, 1.0, "",
                             "|cos q2| floor that keeps J invertible"),
             ParamSpec::integer("frames_to_track", 3, 1, 100000, "",
                                "consecutive frames with a target before tracking"),
             ParamSpec::integer("frames_to_idle", 100, 0, 10000000, "",
                                "frames without target in 'lost' before 'idle'"),
             ParamSpec::string("idle", "hold", "idle behaviour", {"hold", "return_home"}),
             ParamSpec::real_list("home_q_rad", {0.0, 0.0}, "rad", "home pose (return_home)"),
             ParamSpec::real_list("hold_kp_nm_per_rad", {2.0, 0.3}, "N m/rad",
                                  "joint PD for hold / home"),
             ParamSpec::real_list("hold_kv_nm_s_per_rad", {0.1, 0.015}, "N m s/rad",
                                  "joint PD for hold / home"),
             ParamSpec::string("joint_names", "pan,tilt",
                               "names of q1 and q2 in /head/joint_states and the command"),
             ParamSpec::string("report_dir", "",
                               "tests: write <name>.csv (one row per image) on deactivate")},
        .publishes = {runtime::port<msgs::avs_msgs::TargetObservation>("target", "/target"),
                      runtime::port<msgs::avs_msgs::JointTorqueCommand>(
                          "torque_command", "/head/torque_command", keep_last_1),
                      runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing")},
        .subscribes = {
            runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image", keep_last_4),
            runtime::port<msgs::sensor_msgs::JointState>("joint_states", "/head/joint_states")}};
  }

  explicit TrackingComponent(ComponentContext& ctx)
      : Component(ctx),
        target_(ctx.publisher<msgs::avs_msgs::TargetObservation>("target")),
        command_(ctx.publisher<msgs::avs_msgs::JointTorqueCommand>("torque_command")),
        timing_(ctx.publisher<msgs::avs_msgs::StageTiming>("timing")),
        tracker_(make_config(ctx)),
        enabled_(ctx.param<bool>("enabled")),
        report_dir_(ctx.param<std::string>("report_dir")) {
    camera_ = {ctx.param<double>("fx_px"), ctx.param<double>("fy_px"), ctx.param<double>("cx_px"),
               ctx.param<double>("cy_px")};
    moments_.depth_min_m = ctx.param<double>("depth_min_m");
    moments_.depth_max_m = ctx.param<double>("depth_max_m");
    moments_.min_area_px = ctx.param<double>("min_area_px");
    if (!(moments_.depth_min_m < moments_.depth_max_m)) {
      throw std::invalid_argument("depth_min_m must be below depth_max_m");
    }
    const std::string names = ctx.param<std::string>("joint_names");
    const auto comma = names.find(',');
    if (comma == std::string::npos) throw std::invalid_argument("joint_names needs 'pan,tilt'");
    joint_names_ = {names.substr(0, comma), names.substr(comma + 1)};
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { on_joints(*m); });
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth(*m); });
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
  static TrackerConfig make_config(ComponentContext& ctx) {
    TrackerConfig c;
    c.law.jacobian = ctx.param<std::string>("jacobian") == "full" ? JacobianForm::full
                                                                  : JacobianForm::simplified;
    c.law.fx_px = ctx.param<double>("fx_px");
    c.law.fy_px = ctx.param<double>("fy_px");
    c.law.a_m = ctx.param<double>("a_m");
    c.law.kp_nm_per_rad = pair(ctx.param<std::vector<double>>("kp_nm_per_rad"), "kp_nm_per_rad");
    c.law.kv_nm_s_per_rad =
        pair(ctx.param<std::vector<double>>("kv_nm_s_per_rad"), "kv_nm_s_per_rad");
    c.law.m_d_px = pair(ctx.param<std::vector<double>>("m_d_px"), "m_d_px");
    c.law.max_torque_nm = pair(ctx.param<std::vector<double>>("max_torque_nm"), "max_torque_nm");
    c.law.min_cos_q2 = ctx.param<double>("min_cos_q2");
    c.frames_to_track = ctx.param<int>("frames_to_track");
    c.frames_to_idle = ctx.param<int>("frames_to_idle");
    c.idle = ctx.param<std::string>("idle") == "return_home" ? IdleBehaviour::return_home
                                                             : IdleBehaviour::hold;
    c.home_q_rad = pair(ctx.param<std::vector<double>>("home_q_rad"), "home_q_rad");
    c.hold_kp_nm_per_rad =
        pair(ctx.param<std::vector<double>>("hold_kp_nm_per_rad"), "hold_kp_nm_per_rad");
    c.hold_kv_nm_s_per_rad =
        pair(ctx.param<std::vector<double>>("hold_kv_nm_s_per_rad"), "hold_kv_nm_s_per_rad");
    return c;
  }

  void on_joints(const msgs::sensor_msgs::JointState& m) {
    for (std::uint32_t i = 0; i < m.name._length && i < m.position._length; ++i) {
      const std::string_view name = runtime::get_string(m.name._buffer[i]);
      for (int axis = 0; axis < 2; ++axis) {
        if (name != joint_names_[static_cast<std::size_t>(axis)]) continue;
        joints_.q_rad[axis] = m.position._buffer[i];
        joints_.qd_rad_s[axis] = i < m.velocity._length ? m.velocity._buffer[i] : 0.0;
        have_axis_[axis] = true;
      }
    }
  }

  void on_depth(const msgs::sensor_msgs::Image& image) {
    std::string why;
    const auto layout = runtime::depth_image_layout(image, &why);
    if (!layout) {
      if (!warned_encoding_) log().error(why, ": ignored");
      warned_encoding_ = true;
      return;
    }
    ++images_;
    const auto started = std::chrono::steady_clock::now();
    DepthImageView view;
    view.depth_m = layout->depth_m;
    view.width = layout->width;
    view.height = layout->height;
    view.row_stride_floats = static_cast<std::size_t>(layout->row_stride_floats);
    TargetObservation obs = measure_target(view, camera_, moments_);  // Eqs. 7-9
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
    auto msg = runtime::make_sample<msgs::avs_msgs::TargetObservation>();
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
    auto msg = runtime::make_sample<msgs::avs_msgs::StageTiming>();
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->stage, "tracking");
    msg->processing_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count();
    timing_.publish(std::move(msg));
  }

  void publish_command(const Eigen::Vector2d& torque) {
    auto msg = runtime::make_sample<msgs::avs_msgs::JointTorqueCommand>();
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
  Tracker tracker_;
  bool enabled_;
  std::string report_dir_;
  CameraIntrinsics camera_;
  MomentsConfig moments_;
  std::array<std::string, 2> joint_names_;
  JointState joints_;
  bool have_axis_[2] = {false, false};
  bool warned_encoding_ = false;
  bool warned_no_joints_ = false;
  std::uint64_t images_ = 0;
  std::uint64_t frames_with_target_ = 0;
  std::string csv_;
};

AVS_REGISTER_COMPONENT(TrackingComponent);

}  // namespace avs::tracking
