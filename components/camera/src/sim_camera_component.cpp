// sim_camera: the simulator as a GigE Vision camera (issue 15 section 3). Aravis's GV fake
// camera (arv_gv_fake_camera_new_full) answers GVCP on `interface` (port 3956) and streams
// GVSP to whoever opens it; its fill-pattern callback (arv_fake_camera_set_fill_pattern)
// writes frame k of the simulator's Gray-code sequence (section 4.1: 2n frames per cycle, the
// scene at start_time_s + k / frame_rate_hz, the head at rest) into each buffer, with the
// camera frame id of k (16-bit GigE ids from first_frame_id, 0 skipped) and the timestamp
// k / frame_rate_hz (an ideal triggered camera's clock) or the host's clock. Frames listed in
// drop_frames are skipped (their ids never appear) and lost_packet_ratio drops GVSP packets,
// to test what the `camera` component makes of gaps. Frames are rendered live (as fast as the
// renderer goes) or, with prerender_cycles > 0, rendered once at start and repeated (a static
// view at full rate). The fake camera only free-runs: its hardware-trigger mode sends nothing.
#include <arv.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "avs/runtime/component.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/simulator.hpp"
#include "glib_handles.hpp"

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

  explicit SimCamera(ComponentContext& ctx)
      : Component(ctx),
        rate_hz_(ctx.param<double>("frame_rate_hz")),
        start_time_s_(ctx.param<double>("start_time_s")),
        first_id_(static_cast<std::uint64_t>(ctx.param<std::int64_t>("first_frame_id"))),
        host_stamps_(ctx.param<std::string>("timestamps") == "host") {
    for (double k : ctx.param<std::vector<double>>("drop_frames")) {
      drop_.insert(static_cast<std::uint64_t>(k));
    }
    sim_ = make_simulator(ctx);
    const auto cycles = ctx.param<std::int64_t>("prerender_cycles");
    const auto per_cycle =
        static_cast<std::uint64_t>(2 * sim_->config().renderer.geometry.layout.bit_count);
    for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(cycles) * per_cycle; ++k) {
      prerendered_.push_back(render(k));
    }
    const std::string interface = ctx.param<std::string>("interface");
    const std::string serial = ctx.param<std::string>("serial");
    fake_.reset(arv_gv_fake_camera_new_full(interface.c_str(), serial.c_str(), nullptr));
    if (fake_ == nullptr || !arv_gv_fake_camera_is_running(fake_.get())) {
      throw runtime::Error("sim_camera: cannot serve a GigE Vision camera on '" + interface +
                           "' (GVCP port 3956): no such interface, or the port is taken by "
                           "another (fake) camera");
    }
    if (const double ratio = ctx.param<double>("lost_packet_ratio"); ratio > 0) {
      // GvFakeCamera's "gvsp-lost-packet-ratio" property came after Aravis 0.8.26 (Debian 12).
      if (g_object_class_find_property(G_OBJECT_GET_CLASS(fake_.get()), "gvsp-lost-packet-ratio") ==
          nullptr) {
        throw runtime::Error("sim_camera: lost_packet_ratio " + std::to_string(ratio) +
                             " needs the GV fake camera's gvsp-lost-packet-ratio property, which "
                             "this Aravis (" +
                             std::to_string(arv_get_major_version()) + "." +
                             std::to_string(arv_get_minor_version()) + "." +
                             std::to_string(arv_get_micro_version()) +
                             ") does not have; use drop_frames");
      }
      g_object_set(fake_.get(), "gvsp-lost-packet-ratio", ratio, nullptr);
    }
    ArvFakeCamera* camera = arv_gv_fake_camera_get_fake_camera(fake_.get());
    arv_fake_camera_set_trigger_frequency(camera, rate_hz_);
    arv_fake_camera_set_fill_pattern(camera, &SimCamera::fill_pattern, this);
    log().info("serving the simulator as GigE Vision camera serial ", serial, " on ", interface,
               ": ", sim_->config().renderer.geometry.camera.width, "x",
               sim_->config().renderer.geometry.camera.height, " Mono8, ", rate_hz_,
               " Hz at most (free-run; the fake camera's trigger mode sends nothing), ",
               prerendered_.empty() ? std::string("rendered live")
                                    : std::to_string(prerendered_.size()) + " frames repeated",
               ", ", drop_.size(), " frames dropped on purpose");
  }

  ~SimCamera() override {
    // Stop the fake camera's thread before the callback's data goes.
    if (fake_)
      arv_fake_camera_set_fill_pattern(arv_gv_fake_camera_get_fake_camera(fake_.get()), nullptr,
                                       nullptr);
    fake_.reset();
  }

  void on_deactivate() override {
    log().info(filled_.load(), " frames sent (", skipped_.load(), " skipped on purpose, ",
               mismatched_.load(), " with a ROI or pixel format other than the scene's)");
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

  /// GigE Vision block id of frame k: 16 bits, 0 skipped.
  std::uint64_t frame_id(std::uint64_t k) const { return (first_id_ - 1 + k) % 65535 + 1; }

  static void fill_pattern(ArvBuffer* buffer, void* self, guint32 /*exposure_time_us*/,
                           guint32 /*gain*/, ArvPixelFormat pixel_format) {
    static_cast<SimCamera*>(self)->fill(buffer, pixel_format);
  }

  /// On the fake camera's thread: frame k into the buffer it is about to send.
  void fill(ArvBuffer* buffer, ArvPixelFormat pixel_format) {
    std::uint64_t k = next_++;
    while (drop_.contains(k)) {
      k = next_++;
      ++skipped_;
    }
    const int width = arv_buffer_get_image_width(buffer);
    const int height = arv_buffer_get_image_height(buffer);
    size_t size = 0;
    auto* data = static_cast<std::uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, &size)));
    const auto& geometry = sim_->config().renderer.geometry.camera;
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    if (pixel_format != ARV_PIXEL_FORMAT_MONO_8 || width != geometry.width ||
        height != geometry.height || data == nullptr) {
      ++mismatched_;
      if (data != nullptr) std::memset(data, 0, std::min<std::size_t>(size, pixels));
    } else if (!prerendered_.empty()) {
      const auto& image = prerendered_[k % prerendered_.size()];
      std::memcpy(data, image.data(), pixels);
    } else {
      const std::vector<std::uint8_t> image = render(k);
      std::memcpy(data, image.data(), pixels);
    }
    arv_buffer_set_frame_id(buffer, frame_id(k));
    const auto period_ns = static_cast<std::uint64_t>(1e9 / rate_hz_);
    arv_buffer_set_timestamp(buffer, host_stamps_
                                         ? static_cast<std::uint64_t>(g_get_real_time()) * 1000
                                         : (k + 1) * period_ns);
    ++filled_;
  }

  double rate_hz_;
  double start_time_s_;
  std::uint64_t first_id_;
  bool host_stamps_;
  std::set<std::uint64_t> drop_;
  std::unique_ptr<sim::Simulator> sim_;
  std::vector<std::vector<std::uint8_t>> prerendered_;
  std::uint64_t next_ = 0;  ///< fake camera thread only
  std::atomic<std::uint64_t> filled_{0};
  std::atomic<std::uint64_t> skipped_{0};
  std::atomic<std::uint64_t> mismatched_{0};
  detail::GObjectPtr<ArvGvFakeCamera> fake_;  ///< last: stopped first
};

AVS_REGISTER_COMPONENT(SimCamera);

}  // namespace avs::camera
