// projector: a DLP LightCrafter 4500 (DLPC350) over USB HID as the rig's pattern source
// (issue 15 section 4, docs/devices.md section 7). At construction it opens the device,
// configures the paper's sequence (1-bit patterns from flash, 18 per cycle, 1000 us exposure
// and period, one TRIG_OUT_1 pulse per pattern to the camera), validates it and starts it; a
// sequence the controller declares invalid fails start-up with its status words (a broken
// configuration). A device that is absent, times out or is unplugged never stops the graph: it
// is reported (log, /diagnostics), reopened every reconnect_period_ms and configured again.
// `transport: emulator` drives avs's DLPC350 emulator instead (no hardware: tests, sim rigs).
// /projector/link_state (std_msgs/String, latched) says "running", "disconnected" or "refused"
// on every change.
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>

#include "avs/projector/dlpc350_emulator.hpp"
#include "avs/projector/projector_link.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/projector/hidapi_transport.hpp"

namespace avs::projector {

using runtime::ComponentContext;
using runtime::ComponentSpec;

namespace {

enum class TransportKind : std::uint8_t { kHid, kEmulator };

/// What the component's parameters set (the defaults are the parameters').
struct ProjectorConfig {
  TransportKind transport = TransportKind::kHid;
  int vendor_id = kUsbVendorId;
  int product_id = kUsbProductId;
  std::string serial;
  int bit_count = 9;              ///< n: 2n patterns per cycle (the camera's bit_count)
  int pattern_count = 0;          ///< 0: 2n (the depth sequence); else this many from flash
  double pattern_rate_hz = 1000;  ///< the camera's frame_rate_hz: one fact for both
  int exposure_us = 0;            ///< 0: the whole pattern period
  SequenceConfig sequence;        ///< the rest of the sequence (counts and times from above)
  int usb_timeout_ms = 200;
  int reconnect_period_ms = 1000;
  int status_period_ms = 1000;
  int timeouts_before_lost = 3;
  bool match_reply_sequence = true;
  int emulator_flash_images = 1;
  double emulator_unplug_at_s = -1;  ///< emulator only: unplug this long after activation
  double emulator_replug_at_s = -1;  ///< ... and plug back in
};

LinkConfig link_config(const ProjectorConfig& c) {
  LinkConfig l;
  l.sequence = c.sequence;
  l.usb_timeout = std::chrono::milliseconds(c.usb_timeout_ms);
  l.reconnect_period = std::chrono::milliseconds(c.reconnect_period_ms);
  l.status_period = std::chrono::milliseconds(c.status_period_ms);
  l.timeouts_before_lost = c.timeouts_before_lost;
  l.match_reply_sequence = c.match_reply_sequence;
  return l;
}

}  // namespace

class ProjectorComponent final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {.type = "projector",
            .description =
                "DLP LightCrafter 4500 (DLPC350) over USB HID: configures, validates and runs "
                "the flash pattern sequence, trigger out 1 to the camera; reconnects when the "
                "device comes back; `transport: emulator` for avs's DLPC350 emulator",
            .parameters = params().specs_with({}),
            .publishes = {runtime::port<msgs::std_msgs::String>(
                "link_state", "/projector/link_state", latched())},
            .subscribes = {},
            .default_mismatches = [] { return params().default_mismatches(); }};
  }

  /// The last link state for late joiners too.
  static runtime::QosProfile latched() {
    runtime::QosProfile q;
    q.durability = runtime::Durability::transient_local;
    q.depth = 1;
    return q;
  }

  static const runtime::ConfigParams<ProjectorConfig>& params() {
    static const auto p =
        runtime::ConfigParams<ProjectorConfig>()
            .choice("transport", AVS_FIELD(transport),
                    std::vector<std::pair<std::string, TransportKind>>{
                        {"hid", TransportKind::kHid}, {"emulator", TransportKind::kEmulator}},
                    "hid: the LightCrafter on USB (hidapi; NOT exercised by avs's tests); "
                    "emulator: avs's DLPC350 emulator, no hardware")
            .integer("vendor_id", AVS_FIELD(vendor_id), 0, 65535, "", "USB vendor id (TI 0x0451)")
            .integer("product_id", AVS_FIELD(product_id), 0, 65535, "",
                     "USB product id (LightCrafter 4500: 0x6401)")
            .string("serial", AVS_FIELD(serial), "USB serial number; empty: the first found")
            .integer("bit_count", AVS_FIELD(bit_count), 1, 64, "",
                     "n code bits: 2n 1-bit patterns per cycle in `avs patterns`' order (the "
                     "camera's and decode's bit_count)")
            .integer("pattern_count", AVS_FIELD(pattern_count), 0, 128, "",
                     "patterns per cycle; 0: 2 x bit_count (the depth sequence of `avs "
                     "patterns`); the calibration sequence: the count `avs calib patterns` "
                     "prints (38 for the paper's projector), with its first_flash_image")
            .real("pattern_rate_hz", AVS_FIELD(pattern_rate_hz), 0.01, 1e6, "Hz",
                  "patterns per second (the camera's frame_rate_hz); the period 1e6 / rate "
                  "must be whole microseconds")
            .integer("exposure_us", AVS_FIELD(exposure_us), 0, 1e8, "us",
                     "pattern exposure; 0: the whole period (else <= period - 230 us)")
            .choice("led", AVS_FIELD(sequence.led),
                    std::vector<std::pair<std::string, Led>>{{"white", Led::kWhite},
                                                             {"red", Led::kRed},
                                                             {"green", Led::kGreen},
                                                             {"blue", Led::kBlue}},
                    "LEDs lit for every pattern")
            .integer("first_flash_image", AVS_FIELD(sequence.first_flash_image), 0, 255, "",
                     "flash image index of `avs patterns`' flash_image_00.bmp")
            .boolean("trigger_out1_invert", AVS_FIELD(sequence.trigger_out1.invert),
                     "TRIG_OUT_1 active low (the camera triggers on its falling edge)")
            .real("trigger_out1_rising_delay_us", AVS_FIELD(sequence.trigger_out1.rising_delay_us),
                  -20.05, 6.86, "us", "TRIG_OUT_1 rising edge delay (107.2 ns steps)")
            .real("trigger_out1_falling_delay_us",
                  AVS_FIELD(sequence.trigger_out1.falling_delay_us), -20.05, 6.86, "us",
                  "TRIG_OUT_1 falling edge delay")
            .integer("usb_timeout_ms", AVS_FIELD(usb_timeout_ms), 1, 10000, "ms",
                     "wait for one reply")
            .integer("reconnect_period_ms", AVS_FIELD(reconnect_period_ms), 10, 600000, "ms",
                     "between attempts to open a missing device")
            .integer("status_period_ms", AVS_FIELD(status_period_ms), 10, 600000, "ms",
                     "between status read-backs")
            .integer("timeouts_before_lost", AVS_FIELD(timeouts_before_lost), 1, 1000, "",
                     "consecutive timeouts after which the device is reopened")
            .boolean("match_reply_sequence", AVS_FIELD(match_reply_sequence),
                     "skip replies whose sequence number is not the request's (late replies); "
                     "false if the firmware does not echo it (not verified on a DLPC350)")
            .integer("emulator_flash_images", AVS_FIELD(emulator_flash_images), 0, 256, "",
                     "emulator: images in its flash")
            .real("emulator_unplug_at_s", AVS_FIELD(emulator_unplug_at_s), -1.0, 1e6, "s",
                  "emulator: unplug it this long after start (-1: never)")
            .real("emulator_replug_at_s", AVS_FIELD(emulator_replug_at_s), -1.0, 1e6, "s",
                  "emulator: plug it back in this long after start (-1: never)");
    return p;
  }

  explicit ProjectorComponent(ComponentContext& ctx)
      : Component(ctx),
        config_(make_config(ctx)),
        link_state_(ctx.publisher<msgs::std_msgs::String>("link_state")) {
    if (const std::string problem = check(config_.sequence); !problem.empty()) {
      throw runtime::Error("projector: " + problem);
    }
    link_ = std::make_unique<ProjectorLink>(link_config(config_), make_opener(ctx));
    // The first attempt now: a sequence the controller refuses stops start-up; a missing
    // device does not (it is retried while the graph runs).
    log_events(link_->step(steady_now()));
    if (link_->state() == LinkState::kRefused) {
      throw runtime::Error("projector: " + link_->last_error());
    }
  }

  void on_activate() override {
    activated_ = steady_now();
    publish_link_state();
    timer_ = context().create_timer(std::chrono::milliseconds(50), [this] { tick(); });
  }

  void on_deactivate() override {
    if (timer_ != 0) context().cancel_timer(timer_);
    timer_ = 0;
    std::lock_guard lock(mutex_);
    log_events(link_->close());
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    std::lock_guard lock(mutex_);
    const LinkCounters& c = link_->counters();
    const auto text = [](std::uint64_t v) { return std::to_string(v); };
    return {{"transport", config_.transport == TransportKind::kHid ? "hid" : "emulator"},
            {"link_state", link_state_name(link_->state())},
            {"device", link_->device_description()},
            {"connects", text(c.connects)},
            {"connect_failures", text(c.connect_failures)},
            {"disconnects", text(c.disconnects)},
            {"usb_timeouts", text(c.timeouts)},
            {"nacks", text(c.nacks)},
            {"bad_replies", text(c.bad_replies)},
            {"status_reads", text(c.status_reads)},
            {"status_faults", text(c.status_faults)},
            {"validation", link_->validation_words()},
            {"status", link_->status_words()},
            {"last_error", link_->last_error()}};
  }

 private:
  static ProjectorConfig make_config(ComponentContext& ctx) {
    ProjectorConfig c = params().make(ctx.parameters());
    const double period_us = 1e6 / c.pattern_rate_hz;
    if (std::abs(period_us - std::round(period_us)) > 1e-6) {
      throw runtime::Error("projector: pattern_rate_hz " + std::to_string(c.pattern_rate_hz) +
                           " gives a period of " + std::to_string(period_us) +
                           " us; the DLPC350 takes whole microseconds");
    }
    c.sequence.pattern_count = c.pattern_count > 0 ? c.pattern_count : 2 * c.bit_count;
    c.sequence.frame_period_us = static_cast<int>(std::lround(period_us));
    c.sequence.exposure_us = c.exposure_us > 0 ? c.exposure_us : c.sequence.frame_period_us;
    return c;
  }

  TransportOpener make_opener(ComponentContext& ctx) {
    if (config_.transport == TransportKind::kEmulator) {
      log().warn(
          "projector: transport emulator: NO projector is driven; avs's DLPC350 "
          "emulator answers the USB protocol (",
          config_.emulator_flash_images, " flash images)");
      emulator_ = std::make_shared<Dlpc350Emulator>(
          EmulatorConfig{.flash_image_count = config_.emulator_flash_images, .busy_reads = 1});
      return emulator_opener(emulator_);
    }
    if (config_.emulator_unplug_at_s >= 0 || config_.emulator_replug_at_s >= 0) {
      throw runtime::Error(
          "projector: emulator_unplug_at_s / emulator_replug_at_s need "
          "transport: emulator");
    }
    if (!hidapi_available()) {
      throw runtime::Error(
          "projector: transport hid, but avs was built without hidapi "
          "(install libhidapi-dev and reconfigure), or use transport: emulator");
    }
    if (ctx.uses_sim_time()) {
      throw runtime::Error(
          "projector: a real projector runs on the wall clock; this graph uses "
          "sim time (use transport: emulator)");
    }
    log().warn(
        "projector: the USB HID path to a real LightCrafter 4500 (hidapi) is NOT "
        "exercised by avs's tests: no projector on the test machine; the DLPC350 "
        "protocol is tested against avs's emulator only (docs/devices.md section 7)");
    return hidapi_opener({static_cast<std::uint16_t>(config_.vendor_id),
                          static_cast<std::uint16_t>(config_.product_id), config_.serial});
  }

  /// Link time: the context's clock (wall, or sim for the emulator) on a steady time line.
  SteadyTime steady_now() { return SteadyTime{} + std::chrono::nanoseconds(context().now().ns); }

  void tick() {
    const SteadyTime now = steady_now();
    if (emulator_) apply_emulator_schedule(now - activated_);
    {
      std::lock_guard lock(mutex_);
      log_events(link_->step(now));
    }
    publish_link_state();
  }

  /// /projector/link_state on every change ("disconnected", "running", "refused").
  void publish_link_state() {
    LinkState state{};
    {
      std::lock_guard lock(mutex_);
      state = link_->state();
    }
    if (published_state_ && *published_state_ == state) return;
    published_state_ = state;
    auto m = runtime::make_sample<msgs::std_msgs::String>();
    runtime::set_string(m->data, link_state_name(state));
    link_state_.publish(std::move(m));
  }

  void apply_emulator_schedule(std::chrono::nanoseconds since_start) {
    const double t = std::chrono::duration<double>(since_start).count();
    if (!unplugged_ && config_.emulator_unplug_at_s >= 0 && t >= config_.emulator_unplug_at_s) {
      unplugged_ = true;
      log().warn("projector: unplugging the emulated DLPC350 (emulator_unplug_at_s)");
      emulator_->unplug();
    }
    if (!replugged_ && config_.emulator_replug_at_s >= 0 && t >= config_.emulator_replug_at_s) {
      replugged_ = true;
      log().info("projector: plugging the emulated DLPC350 back in (emulator_replug_at_s)");
      emulator_->plug_in();
    }
  }

  void log_events(const std::vector<LinkEvent>& events) const {
    for (const LinkEvent& e : events) {
      switch (e.level) {
        case LinkEvent::Level::kInfo:
          log().info("projector: ", e.text);
          break;
        case LinkEvent::Level::kWarn:
          log().warn("projector: ", e.text);
          break;
        case LinkEvent::Level::kError:
          log().error("projector: ", e.text);
          break;
      }
    }
  }

  ProjectorConfig config_;
  runtime::Publisher<msgs::std_msgs::String> link_state_;
  std::optional<LinkState> published_state_;
  std::shared_ptr<Dlpc350Emulator> emulator_;
  runtime::TimerId timer_ = 0;
  SteadyTime activated_{};
  bool unplugged_ = false;
  bool replugged_ = false;
  mutable std::mutex mutex_;  ///< link_ between the timer and diagnostic_values()
  std::unique_ptr<ProjectorLink> link_;
};

AVS_REGISTER_COMPONENT(ProjectorComponent);

}  // namespace avs::projector
