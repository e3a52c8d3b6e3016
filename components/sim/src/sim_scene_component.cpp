// sim_scene: the simulated projector-camera sensor as a capture component (issue 3 item 1).
// A timer at frame_rate_hz ON THE CONTAINER CLOCK renders frame k of the Gray-code sequence
// (section 4.1, Eq. 1; 2n frames per cycle) at scene time start_time_s + k / frame_rate_hz,
// with the head at the latest /sim/head_state (servo sign convention, docs/servo.md section 1)
// extrapolated to the tick, and publishes /camera/pattern, /sim/ground_truth (one message
// per scene object) and /timing (stage "render"). In sim lockstep the frame sequence, the
// images and the ground truth depend only on the graph and the seed.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "avs/decode/calibration_yaml.hpp"
#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/frames.hpp"
#include "avs/msg/convert.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/rejections.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/sensor_profile.hpp"
#include "avs/sim/simulator.hpp"
#include "scene_path.hpp"

namespace avs::sim {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

namespace {

namespace fs = std::filesystem;

/// The built-in scene (`scene` empty): the ken 1 m in front of the head at its home pose,
/// upright, crosspiece across the view (ManipulatorMotionConfig::default_start), static, and
/// a wall 2 m away (outside the 0.3-1.5 m depth window).
SceneFile builtin_scene() {
  SceneFile file;
  SceneObject ken;
  ken.name = "ken";
  ken.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("ken"));
  ken.albedo = 0.7;
  ken.trajectory = std::make_shared<StaticTrajectory>(ManipulatorMotionConfig::default_start());
  file.scene.objects.push_back(ken);
  SceneObject wall = make_background_plane(2.0);
  wall.name = "wall";
  file.scene.objects.push_back(wall);
  return file;
}

/// A trajectory moved by a fixed world translation (the `distance_m` override).
class ShiftedTrajectory final : public Trajectory {
 public:
  ShiftedTrajectory(std::shared_ptr<const Trajectory> inner, Eigen::Vector3d shift_m)
      : inner_(std::move(inner)), shift_m_(std::move(shift_m)) {}
  Eigen::Isometry3d T_world_object(double t_s) const override {
    Eigen::Isometry3d T = inner_->T_world_object(t_s);
    T.translation() += shift_m_;
    return T;
  }

 private:
  std::shared_ptr<const Trajectory> inner_;
  Eigen::Vector3d shift_m_;
};

/// Median of the samples (0 for none).
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

class SimScene final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    runtime::QosProfile keep_last_100;
    keep_last_100.depth = 100;
    // The scene's own defaults, quoted in the descriptions of the overrides (written once, in
    // the cores).
    const SimulatorConfig sim;
    const LateralSwingConfig swing;
    const auto text = [](double v) { return runtime::to_string(runtime::ParamValue(v)); };
    return {
        .type = "sim_scene",
        .description =
            "simulated projector-camera sensor: renders the Gray-code frames of a scene at "
            "frame_rate_hz on the container clock with the head at /sim/head_state; "
            "publishes /camera/pattern, /sim/ground_truth, /timing (stage render)",
        .parameters =
            {ParamSpec::string("scene", "",
                               "scene YAML (docs/sim.md); relative paths are looked up in the "
                               "working directory, the source tree ($AVS_SOURCE_DIR) and its "
                               "launch_config/scenes/, '.yaml' optional; empty: the built-in "
                               "static ken 1 m ahead with a wall at 2 m"),
             ParamSpec::string("object", "",
                               "replace the target's (first object's) mesh: ken, cube, cylinder "
                               "or a PLY/STL/OBJ path (metres); empty: as in the scene"),
             ParamSpec::string("trajectory", "",
                               "replace the target's trajectory, starting from its pose at "
                               "start_time_s; empty: as in the scene",
                               {"", "static", "swing", "manipulator"}),
             ParamSpec::real("swing_speed_m_s", 0.0, 0.0, 20.0, "m/s",
                             "peak speed of a lateral swing (section 7.1); 0: as in the scene "
                             "(lateral_swing default " +
                                 text(swing.peak_speed_mps) + ")"),
             ParamSpec::real("swing_amplitude_m", 0.0, 0.0, 2.0, "m",
                             "amplitude of a lateral swing; 0: as in the scene (default " +
                                 text(swing.amplitude_m) + ")"),
             ParamSpec::real("distance_m", 0.0, 0.0, 10.0, "m",
                             "shift the target along world X so that it starts this far from "
                             "the pan axis; 0: as in the scene"),
             ParamSpec::integer("seed", -1, -1, 1e15, "",
                                "sensor noise seed (sensor.noise_seed); -1: as in the scene "
                                "(default " +
                                    std::to_string(sim.renderer.noise_seed) + ")"),
             ParamSpec::real("noise_sigma_dn", -1.0, -1.0, 100.0, "DN",
                             "sensor noise sigma; -1: as in the scene (default " +
                                 text(sim.renderer.noise_sigma_dn) + ")"),
             ParamSpec::string("sensor_profile", "",
                               "optics and sensor effects (docs/sim.md, sensor profiles): "
                               "ideal (sharp pinhole optics, Gaussian noise, matte paint) or "
                               "realistic (defocus, shot and read noise, gloss, texture, "
                               "flicker, motion blur); empty: as in the scene (sensor.profile, "
                               "default ideal)",
                               {"", "ideal", "realistic"}),
             ParamSpec::integer("motion_blur_samples", 0, 0, 64, "",
                                "poses averaged over the exposure; 0: as in the scene "
                                "(default " +
                                    std::to_string(sim.motion_blur_samples) + "; 1 = no blur)"),
             ParamSpec::real("frame_rate_hz", 0.0, 0.0, 100000.0, "Hz",
                             "frame rate; 0: the scene's sensor.frame_rate_hz (default " +
                                 text(sim.frame_rate_hz) + ", section 3.1)"),
             ParamSpec::real("start_time_s", 0.0, std::nullopt, std::nullopt, "s",
                             "scene time of frame 0: frame k shows the scene at "
                             "start_time_s + k / frame_rate_hz"),
             ParamSpec::real("initial_pan_rad", 0.0, -3.2, 3.2, "rad",
                             "head pan until the first /sim/head_state (servo convention)"),
             ParamSpec::real("initial_tilt_rad", 0.0, -1.6, 1.6, "rad",
                             "head tilt until the first /sim/head_state"),
             ParamSpec::string("calibration_file", "",
                               "sensor geometry YAML the renderer uses (decode's format, "
                               "docs/decode.md; camera distortion rendered); empty: the "
                               "paper's sensor, default_sensor_geometry()"),
             ParamSpec::string("true_calibration_file", "",
                               "when set, the renderer uses this sensor geometry instead of "
                               "calibration_file: the simulator's truth, against which a "
                               "recovered calibration given to decode is tested (issue 14)")},
        .publishes =
            {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern", keep_last_4),
             runtime::port<msgs::avs_msgs::GroundTruth>("ground_truth", "/sim/ground_truth"),
             runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing", keep_last_100)},
        .subscribes = {
            runtime::port<msgs::sensor_msgs::JointState>("head_state", "/sim/head_state")}};
  }

  explicit SimScene(ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        truth_(ctx.publisher<msgs::avs_msgs::GroundTruth>("ground_truth")),
        timing_(ctx.publisher<msgs::avs_msgs::StageTiming>("timing")),
        start_time_s_(ctx.param<double>("start_time_s")),
        rejected_(ctx.log(), "/sim/head_state") {
    SceneFile file = load(ctx);
    sim_ = std::make_unique<Simulator>(std::move(file.config), std::move(file.scene));
    head_.pan_rad = ctx.param<double>("initial_pan_rad");
    head_.tilt_rad = ctx.param<double>("initial_tilt_rad");
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "head_state",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { on_head_state(*m); });
    const SimulatorConfig& c = sim_->config();
    std::string objects;
    for (const SceneObject& o : sim_->scene().objects) objects += " " + o.name;
    log().info("scene ", scene_name_, ":", objects, "; ", c.frame_rate_hz, " Hz on the ",
               ctx.uses_sim_time() ? "simulated" : "wall", " clock, noise ",
               c.renderer.noise_sigma_dn, " DN seed ", c.renderer.noise_seed, ", blur samples ",
               c.motion_blur_samples, ", ",
               c.renderer.effects.changes_pattern_light() ||
                       !c.renderer.effects.camera.is_ideal() || c.renderer.effects.lens.blurs()
                   ? "optics and sensor effects on (docs/sim.md)"
                   : "ideal optics and sensor");
  }

  void on_activate() override {
    const double rate = sim_->config().frame_rate_hz;
    const auto period = runtime::Duration(static_cast<std::int64_t>(std::llround(1e9 / rate)));
    timer_ = context().create_timer(period, [this] { tick(); });
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    return {rejected_.diagnostic()};
  }

  void on_deactivate() override {
    std::vector<double> times = render_ms_;
    const double span_s =
        frames_ > 1 ? static_cast<double>((last_stamp_ - first_stamp_).count()) * 1e-9 : 0.0;
    log().info("rendered ", frames_, " frames (", cycles(), " full cycles) in ", span_s,
               " s of clock time; render time median ", median(times), " ms (last ", times.size(),
               " frames); head state ",
               have_head_ ? "from /sim/head_state" : "never received (initial angles used)");
  }

 private:
  SceneFile load(ComponentContext& ctx) {
    const std::string scene = ctx.param<std::string>("scene");
    SceneFile file;
    if (scene.empty()) {
      file = builtin_scene();
      scene_name_ = "(built-in static ken)";
    } else {
      scene_name_ = resolve_scene_path(scene);
      file = load_scene(scene_name_);
    }
    if (file.scene.objects.empty()) throw std::runtime_error(scene_name_ + ": no objects");
    SceneObject& target = file.scene.objects.front();
    const std::string object = ctx.param<std::string>("object");
    if (!object.empty()) {
      const auto names = geometry::builtin_model_names();
      const bool builtin = std::find(names.begin(), names.end(), object) != names.end();
      target.mesh = std::make_shared<const geometry::Mesh>(
          builtin ? geometry::load_mesh(geometry::default_models_dir() + "/" + object + ".ply")
                  : geometry::load_mesh(object));
      target.name = builtin ? object : fs::path(object).stem().string();
    }
    const double t0 = start_time_s_;
    const std::string trajectory = ctx.param<std::string>("trajectory");
    const Eigen::Isometry3d T_start = target.trajectory->T_world_object(t0);
    if (trajectory == "static") {
      target.trajectory = std::make_shared<StaticTrajectory>(T_start);
    } else if (trajectory == "swing") {
      LateralSwingConfig swing;
      swing.T_world_object_centre = T_start;
      swing.start_time_s = t0;
      target.trajectory = std::make_shared<LateralSwingTrajectory>(swing);
    } else if (trajectory == "manipulator") {
      ManipulatorMotionConfig motion;
      motion.T_world_object_start = T_start;
      motion.start_time_s = t0 + motion.start_time_s;
      target.trajectory = std::make_shared<ManipulatorTrajectory>(motion);
    }
    const double speed = ctx.param<double>("swing_speed_m_s");
    const double amplitude = ctx.param<double>("swing_amplitude_m");
    if (speed > 0 || amplitude > 0) {
      const auto* swing = dynamic_cast<const LateralSwingTrajectory*>(target.trajectory.get());
      if (swing == nullptr) {
        throw std::invalid_argument(
            "swing_speed_m_s / swing_amplitude_m apply to a lateral swing, but the target '" +
            target.name + "' of " + scene_name_ +
            " does not swing (use trajectory: swing or a lateral_swing scene)");
      }
      LateralSwingConfig c = swing->config();
      if (speed > 0) c.peak_speed_mps = speed;
      if (amplitude > 0) c.amplitude_m = amplitude;
      target.trajectory = std::make_shared<LateralSwingTrajectory>(c);
    }
    if (const double distance = ctx.param<double>("distance_m"); distance > 0) {
      const double x0 = target.trajectory->T_world_object(t0).translation().x();
      target.trajectory = std::make_shared<ShiftedTrajectory>(
          target.trajectory, Eigen::Vector3d(distance - x0, 0.0, 0.0));
    }
    SimulatorConfig& c = file.config;
    if (const auto seed = ctx.param<std::int64_t>("seed"); seed >= 0) {
      c.renderer.noise_seed = static_cast<std::uint64_t>(seed);
    }
    if (const std::string profile = ctx.param<std::string>("sensor_profile"); !profile.empty()) {
      apply_sensor_profile(parse_sensor_profile(profile), c);
    }
    if (const double sigma = ctx.param<double>("noise_sigma_dn"); sigma >= 0) {
      c.renderer.noise_sigma_dn = sigma;
    }
    if (const auto n = ctx.param<std::int64_t>("motion_blur_samples"); n > 0) {
      c.motion_blur_samples = static_cast<int>(n);
    }
    if (const double rate = ctx.param<double>("frame_rate_hz"); rate > 0) c.frame_rate_hz = rate;
    std::string calibration = ctx.param<std::string>("true_calibration_file");
    if (calibration.empty()) calibration = ctx.param<std::string>("calibration_file");
    if (!calibration.empty()) {
      c.renderer.geometry = decode::load_sensor_geometry_yaml(calibration);
      log().info("sensor geometry from ", calibration);
    }
    return file;
  }

  /// A head state the renderer cannot use (no pan or tilt joint, a non-finite angle or rate)
  /// is rejected, counted and logged (rate-limited); the last good one stays (issue 20 2).
  void on_head_state(const msgs::sensor_msgs::JointState& m) {
    bool pan = false, tilt = false;
    HeadState h = head_;
    for (std::uint32_t i = 0; i < m.name._length && i < m.position._length; ++i) {
      const std::string_view name = runtime::get_string(m.name._buffer[i]);
      const double v = i < m.velocity._length ? m.velocity._buffer[i] : 0.0;
      if (name != "pan" && name != "tilt") continue;
      if (!std::isfinite(m.position._buffer[i]) || !std::isfinite(v)) {
        rejected_.reject(std::string(name) + " position or velocity not finite");
        return;
      }
      if (name == "pan") {
        h.pan_rad = m.position._buffer[i];
        h.pan_rate_rad_s = v;
        pan = true;
      } else {
        h.tilt_rad = m.position._buffer[i];
        h.tilt_rate_rad_s = v;
        tilt = true;
      }
    }
    if (!pan || !tilt) {
      rejected_.reject("no joints named 'pan' and 'tilt' (with positions)");
      return;
    }
    head_ = h;
    head_stamp_ = runtime::from_ros_time(m.header.stamp);
    have_head_ = true;
  }

  /// The head at `now`: the latest state, extrapolated with its rates over at most 10 ms.
  HeadState head_at(runtime::Time now) const {
    HeadState h = head_;
    if (!have_head_) return h;
    const double dt = static_cast<double>((now - head_stamp_).count()) * 1e-9;
    if (dt > 0 && dt <= 0.01) {
      h.pan_rad += h.pan_rate_rad_s * dt;
      h.tilt_rad += h.tilt_rate_rad_s * dt;
    }
    return h;
  }

  void tick() {
    const runtime::Time now = context().now();
    const std::uint64_t k = frames_;
    const double t_scene = start_time_s_ + sim_->frame_time_s(k);
    const HeadState head = head_at(now);
    const auto start = std::chrono::steady_clock::now();
    SimFrame frame = sim_->render(k, t_scene, head);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (render_ms_.size() < kKeptTimes) {
      render_ms_.push_back(ms);
    } else {
      render_ms_[k % kKeptTimes] = ms;
    }
    if (frames_ == 0) first_stamp_ = now;
    last_stamp_ = now;
    ++frames_;
    publish_pattern(frame, now);
    publish_truth(frame, now);
    auto timing = timing_.loan();  // every field set below
    runtime::to_ros_time(now, timing->header.stamp);
    runtime::set_string(timing->header.frame_id, geometry::frame::kCameraOptical);
    runtime::set_string(timing->stage, "render");
    timing->processing_ms = ms;
    timing_.publish(std::move(timing));
  }

  void publish_pattern(const SimFrame& frame, runtime::Time stamp) {
    auto m = pattern_.loan();  // every field set below
    runtime::to_ros_time(stamp, m->header.stamp);
    runtime::set_string(m->header.frame_id, geometry::frame::kCameraOptical);
    auto& image = m->image;
    image.header.stamp = m->header.stamp;
    runtime::set_string(image.header.frame_id, geometry::frame::kCameraOptical);
    runtime::set_string(image.encoding, "mono8");
    image.width = static_cast<std::uint32_t>(frame.image.width);
    image.height = static_cast<std::uint32_t>(frame.image.height);
    image.step = image.width;
    image.is_bigendian = 0;
    runtime::resize_sequence(image.data, static_cast<std::uint32_t>(frame.image.pixels.size()));
    std::copy(frame.image.pixels.begin(), frame.image.pixels.end(), image.data._buffer);
    m->bit_index = static_cast<std::uint8_t>(frame.pattern.bit_index);
    m->bit_count = static_cast<std::uint8_t>(sim_->config().renderer.geometry.layout.bit_count);
    m->positive = frame.pattern.positive;
    m->cycle = frame.pattern.cycle;
    m->pan_rad = frame.truth.head.pan_rad;
    m->tilt_rad = frame.truth.head.tilt_rad;
    pattern_.publish(std::move(m));
  }

  void publish_truth(const SimFrame& frame, runtime::Time stamp) {
    for (const ObjectTruth& o : frame.truth.objects) {
      auto m = truth_.loan();  // every field set below
      runtime::to_ros_time(stamp, m->header.stamp);
      runtime::set_string(m->header.frame_id, geometry::frame::kWorld);
      runtime::set_string(m->object_name, o.name);
      msg::to_pose(o.T_world_object, m->pose_world);
      msg::to_pose(o.T_camera_object, m->pose_camera);
      m->pan_rad = frame.truth.head.pan_rad;
      m->tilt_rad = frame.truth.head.tilt_rad;
      m->pan_velocity_rad_s = frame.truth.head.pan_rate_rad_s;
      m->tilt_velocity_rad_s = frame.truth.head.tilt_rate_rad_s;
      truth_.publish(std::move(m));
    }
  }

  std::uint64_t cycles() const {
    return frames_ /
           static_cast<std::uint64_t>(2 * sim_->config().renderer.geometry.layout.bit_count);
  }

  static constexpr std::size_t kKeptTimes = 100000;

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  runtime::Publisher<msgs::avs_msgs::GroundTruth> truth_;
  runtime::Publisher<msgs::avs_msgs::StageTiming> timing_;
  double start_time_s_;
  runtime::SampleRejections rejected_;  ///< /sim/head_state samples not used
  std::string scene_name_;
  std::unique_ptr<Simulator> sim_;
  HeadState head_;
  runtime::Time head_stamp_;
  bool have_head_ = false;
  std::uint64_t frames_ = 0;
  runtime::Time first_stamp_, last_stamp_;
  std::vector<double> render_ms_;
  runtime::TimerId timer_ = 0;
};

AVS_REGISTER_COMPONENT(SimScene);

}  // namespace avs::sim
