// sim_camera: the simulator as a GigE Vision camera (issue 15 section 3). Aravis's GV fake
// camera (arv_gv_fake_camera_new_full) answers GVCP on `interface` (port 3956) and streams
// GVSP to whoever opens it; its fill-pattern callback (arv_fake_camera_set_fill_pattern)
// writes frame k of the simulator's Gray-code sequence (section 4.1: 2n frames per cycle, the
// scene at start_time_s + k / frame_rate_hz, the head at rest) into each buffer, with the
// camera frame id of k (16-bit GigE ids from first_frame_id, 0 skipped) and the timestamp
// (k + 1) / frame_rate_hz (an ideal triggered camera's clock) or the host's clock. Frames in
// drop_frames are skipped (their ids never appear) and lost_packet_ratio drops GVSP packets
// (Aravis > 0.8.26 only; refused on Debian 12's 0.8.26), to test what the `camera` component
// makes of gaps. Frames are rendered live (as fast as the renderer goes) or, with
// prerender_cycles > 0, rendered once at start and repeated (a static view at full rate). The
// fake camera only free-runs: its hardware-trigger mode sends nothing.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "avs/runtime/component.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/simulator.hpp"
#include "sim_gige_camera.hpp"

namespace avs::camera {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class SimCamera final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {
        .type = "sim_camera",
        .description =
            "the simulator served as a GigE Vision camera (Aravis GV fake camera) "
            "for the camera component: Gray-code frames of a scene over GVCP/GVSP",
        .parameters =
            {ParamSpec::string("interface", "127.0.0.1",
                               "network interface (name or IPv4 address) to serve GVCP/GVSP on"),
             ParamSpec::string("serial", "AVSSIM01", "the camera's serial number"),
             ParamSpec::string("scene", "",
                               "scene YAML (docs/sim.md; absolute or from the working "
                               "directory); empty: a plane plane_x_m ahead of the head"),
             ParamSpec::real("plane_x_m", 1.04, 0.1, 100.0, "m",
                             "the built-in plane's distance from the pan axis (1 m from the "
                             "camera)"),
             ParamSpec::real("frame_rate_hz", 1000.0, 1.0, 100000.0, "Hz",
                             "pattern rate: frame k shows the scene at start_time_s + k / rate"),
             ParamSpec::real("start_time_s", 0.0, std::nullopt, std::nullopt, "s",
                             "scene time of frame 0"),
             ParamSpec::integer("prerender_cycles", 0, 0, 1000, "",
                                "0: render each frame live; N: render N cycles at start and "
                                "repeat them (static view, full rate)"),
             ParamSpec::integer("first_frame_id", 1, 1, 65535, "",
                                "camera frame id of frame 0 (16-bit, wraps 65535 -> 1)"),
             ParamSpec::real_list("drop_frames", {}, "",
                                  "frame numbers k never sent (their ids are skipped)"),
             ParamSpec::real("lost_packet_ratio", 0.0, 0.0, 1.0, "",
                             "fraction of GVSP packets dropped (the fake camera never resends); "
                             "needs Aravis > 0.8.26 (refused otherwise)"),
             ParamSpec::string("timestamps", "frame_index",
                               "frame_index: k / frame_rate_hz (an ideal triggered camera's "
                               "clock); host: the host's realtime clock when filled",
                               {"frame_index", "host"})},
        .publishes = {},
        .subscribes = {}};
  }

  explicit SimCamera(ComponentContext& ctx) : Component(ctx) {
    SimGigECameraConfig c;
    c.interface = ctx.param<std::string>("interface");
    c.serial = ctx.param<std::string>("serial");
    c.frame_rate_hz = ctx.param<double>("frame_rate_hz");
    c.first_frame_id = static_cast<std::uint64_t>(ctx.param<std::int64_t>("first_frame_id"));
    for (double k : ctx.param<std::vector<double>>("drop_frames")) {
      c.drop_frames.insert(static_cast<std::uint64_t>(k));
    }
    c.host_timestamps = ctx.param<std::string>("timestamps") == "host";
    c.lost_packet_ratio = ctx.param<double>("lost_packet_ratio");
    rate_hz_ = c.frame_rate_hz;
    start_time_s_ = ctx.param<double>("start_time_s");
    sim_ = make_simulator(ctx);
    const auto cycles = ctx.param<std::int64_t>("prerender_cycles");
    const auto per_cycle =
        static_cast<std::uint64_t>(2 * sim_->config().renderer.geometry.layout.bit_count);
    for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(cycles) * per_cycle; ++k) {
      prerendered_.push_back(render(k));
    }
    const auto& size = sim_->config().renderer.geometry.camera;
    camera_ = std::make_unique<SimGigECamera>(
        c, size.width, size.height, [this](std::uint64_t k, std::uint8_t* out) {
          if (!prerendered_.empty()) {
            const auto& image = prerendered_[k % prerendered_.size()];
            std::copy(image.begin(), image.end(), out);
          } else {
            const std::vector<std::uint8_t> image = render(k);
            std::copy(image.begin(), image.end(), out);
          }
        });
    log().info("serving the simulator as GigE Vision camera serial ", c.serial, " on ", c.interface,
               ": ", size.width, "x", size.height, " Mono8, ", rate_hz_,
               " Hz at most (free-run; the fake camera's trigger mode sends nothing), ",
               prerendered_.empty() ? std::string("rendered live")
                                    : std::to_string(prerendered_.size()) + " frames repeated",
               ", ", c.drop_frames.size(), " frames dropped on purpose");
  }

  void on_deactivate() override {
    log().info(camera_->frames_sent(), " frames sent (", camera_->frames_skipped(),
               " skipped on purpose, ", camera_->frames_mismatched(),
               " with a ROI or pixel format other than the scene's)");
  }

 private:
  std::unique_ptr<sim::Simulator> make_simulator(ComponentContext& ctx) {
    const std::string scene = ctx.param<std::string>("scene");
    sim::SimulatorConfig config;
    sim::Scene objects{{sim::make_background_plane(ctx.param<double>("plane_x_m"))}};
    if (!scene.empty()) {
      sim::SceneFile file = sim::load_scene(scene);
      config = file.config;
      objects = std::move(file.scene);
    }
    config.frame_rate_hz = rate_hz_;
    return std::make_unique<sim::Simulator>(config, std::move(objects));
  }

  std::vector<std::uint8_t> render(std::uint64_t k) {
    sim::SimFrame frame =
        sim_->render(k, start_time_s_ + static_cast<double>(k) / rate_hz_, sim::HeadState{});
    return std::move(frame.image.pixels);
  }

  double rate_hz_ = 0;
  double start_time_s_ = 0;
  std::unique_ptr<sim::Simulator> sim_;  ///< the fake camera's thread only, once serving
  std::vector<std::vector<std::uint8_t>> prerendered_;
  std::unique_ptr<SimGigECamera> camera_;  ///< last: stops serving before the rest goes
};

AVS_REGISTER_COMPONENT(SimCamera);

}  // namespace avs::camera
