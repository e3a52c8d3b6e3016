// camera: a GenICam camera (GigE Vision, USB3 Vision) through Aravis 0.8 as the graph's
// capture component (issue 15, docs/devices.md). Configures the camera's features from the
// parameters at construction (a rejected feature fails start-up with one line naming it),
// streams into a fixed pool of buffers on its own thread (wall clock only) and labels each
// complete frame with the PatternSequencer: labelled frames go out on /camera/pattern
// (avs_msgs/PatternFrame, the camera buffer lent to the message, no copy); every frame, at
// most image_raw_rate_hz, on /camera/image_raw. /diagnostics counts frames received,
// incomplete buffers, missing ids, resent packets, underruns (no free buffer: back-pressure),
// the current rate and the sequencer's gaps and locks.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include <dds/dds.h>

#include "aravis_camera.hpp"
#include "avs/camera/camera_config.hpp"
#include "avs/camera/pattern_sequencer.hpp"
#include "avs/geometry/frames.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/runtime/lent_sample_pool.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::camera {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class CameraComponent final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    runtime::QosProfile raw_qos;
    raw_qos.reliability = runtime::Reliability::best_effort;
    raw_qos.depth = 2;
    return {.type = "camera",
            .description =
                "GenICam camera (GigE Vision / USB3 Vision) through Aravis: features from the "
                "parameters, buffer pool, PatternSequencer labels -> /camera/pattern, optional "
                "throttled /camera/image_raw; wall clock only",
            .parameters = params().specs_with(
                {ParamSpec::string("frame_id", geometry::frame::kCameraOptical,
                                   "header.frame_id of the images (the /tf frame)")}),
            .publishes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                                      keep_last_4),
                          runtime::port<msgs::sensor_msgs::Image>("image_raw", "/camera/image_raw",
                                                                  raw_qos)},
            .subscribes = {},
            .default_mismatches = [] { return params().default_mismatches(); }};
  }

  /// Parameters bound to CameraConfig (its defaults are the parameters').
  static const runtime::ConfigParams<CameraConfig>& params() {
    static const auto p =
        runtime::ConfigParams<CameraConfig>()
            .string("device_id", AVS_FIELD(device_id),
                    "Aravis device id, serial number or IP address (arv-tool-0.8 lists them); "
                    "empty: the only camera found")
            .string("pixel_format", AVS_FIELD(pixel_format), "PixelFormat", {"Mono8"})
            .integer("width", AVS_FIELD(width), 1, 65535, "px", "Width (ROI)")
            .integer("height", AVS_FIELD(height), 1, 65535, "px", "Height (ROI)")
            .integer("offset_x", AVS_FIELD(offset_x), -1, 65535, "px", "OffsetX; -1: centred")
            .integer("offset_y", AVS_FIELD(offset_y), -1, 65535, "px", "OffsetY; -1: centred")
            .real("exposure_time_us", AVS_FIELD(exposure_time_us), 0.0, 1e7, "us",
                  "ExposureTime; 0: as the camera has it")
            .live()
            .real("gain", AVS_FIELD(gain), -1.0, 1e6, "", "Gain (or GainRaw); -1: as it is")
            .live()
            .choice("trigger_mode", AVS_FIELD(trigger_mode),
                    std::vector<std::pair<std::string, TriggerMode>>{
                        {"hardware", TriggerMode::kHardware}, {"free_run", TriggerMode::kFreeRun}},
                    "hardware: TriggerMode On from trigger_source (the projector's trigger out, "
                    "the rig); free_run: TriggerMode Off, AcquisitionFrameRate = frame_rate_hz")
            .string("trigger_source", AVS_FIELD(trigger_source), "TriggerSource (hardware mode)")
            .string("trigger_activation", AVS_FIELD(trigger_activation),
                    "TriggerActivation (hardware mode)")
            .real("frame_rate_hz", AVS_FIELD(frame_rate_hz), 0.1, 100000.0, "Hz",
                  "the projector's pattern rate: AcquisitionFrameRate in free_run, the "
                  "sequencer's frame period in both modes")
            .integer("packet_size", AVS_FIELD(packet_size), 0, 65535, "bytes",
                     "GigE GevSCPSPacketSize; 0: the largest the path takes (Aravis probes)")
            .integer("socket_buffer_bytes", AVS_FIELD(socket_buffer_bytes), 0, 1 << 30, "bytes",
                     "GigE receive socket buffer; 0: one payload (net.core.rmem_max caps it)")
            .boolean("packet_resend", AVS_FIELD(packet_resend), "GigE: request lost packets again")
            .integer("buffer_count", AVS_FIELD(buffer_count), 2, 4096, "",
                     "stream buffers, allocated once (frames held downstream keep theirs)")
            .integer("buffer_timeout_ms", AVS_FIELD(buffer_timeout_ms), 1, 10000, "ms",
                     "wait for a buffer before checking for stop")
            .choice("stamp_source", AVS_FIELD(stamp_source),
                    std::vector<std::pair<std::string, StampSource>>{
                        {"host_mapped", StampSource::kHostMapped},
                        {"camera", StampSource::kCamera},
                        {"host_arrival", StampSource::kHostArrival}},
                    "header.stamp: host_mapped = camera timestamp + the smallest host-camera "
                    "offset seen; camera = the camera's clock as is; host_arrival = arrival")
            .real("image_raw_rate_hz", AVS_FIELD(image_raw_rate_hz), 0.0, 100000.0, "Hz",
                  "/camera/image_raw at most this often (every frame, labelled or not); 0: off")
            .live()
            .integer("bit_count", AVS_FIELD(sequencer.bit_count), 2, 15, "",
                     "n code bits of the projected sequence (2n frames per cycle)")
            .integer("frame_id_bits", AVS_FIELD(sequencer.frame_id_bits), 2, 64, "",
                     "camera frame id width: 16 for GigE Vision block ids (0 skipped), 64")
            .boolean("frame_id_zero_skipped", AVS_FIELD(sequencer.frame_id_zero_skipped),
                     "frame ids wrap to 1, not 0 (GigE Vision)")
            .real("gap_tolerance_periods", AVS_FIELD(sequencer.gap_tolerance_periods), 0.0, 0.5, "",
                  "a step of k ids must come with a timestamp step of k +- this many periods")
            .integer("max_bridged_gap_frames", AVS_FIELD(sequencer.max_bridged_gap_frames), 0, 1e6,
                     "", "longest id gap crossed without losing the lock")
            .integer("lock_cycles", AVS_FIELD(sequencer.lock_cycles), 1, 100, "",
                     "cycles that must show the pattern structure before labelling")
            .integer("threshold_psi", AVS_FIELD(sequencer.threshold_psi), 0, 255, "",
                     "Eq. 2 threshold for the sequencer's bit transitions")
            .live()
            .real("pair_sum_match_max", AVS_FIELD(sequencer.pair_sum_match_max), 0.0, 10.0, "",
                  "a true pair's sum differs from the previous pair's by at most this (relative)")
            .live()
            .real("pair_sum_mismatch_min", AVS_FIELD(sequencer.pair_sum_mismatch_min), 0.0, 10.0,
                  "", "misaligned couples differ by at least this (relative)")
            .live()
            .boolean("verify_pairs", AVS_FIELD(sequencer.verify_pairs),
                     "check each labelled pair's structure before publishing it")
            .live()
            .integer("relock_cycle_jump", AVS_FIELD(sequencer.relock_cycle_jump), 2, 1e6, "",
                     "cycle numbers skipped (at least) after a lost lock");
    return p;
  }

  explicit CameraComponent(ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        image_raw_(ctx.publisher<msgs::sensor_msgs::Image>("image_raw")),
        config_(make_config(ctx)),
        frame_id_(ctx.param<std::string>("frame_id")),
        sequencer_(config_.sequencer),
        rejected_(ctx.log(), "camera buffer") {
    if (ctx.uses_sim_time()) {
      throw runtime::Error(
          "camera: a camera runs on the wall clock; this graph uses sim time (use sim_scene, "
          "or sim_camera + camera in a wall-clock graph)");
    }
    camera_ = std::make_unique<AravisCamera>(config_);
    log().info(camera_->description());
    if (const std::string untested = camera_->untested_path(); !untested.empty()) {
      log().warn(untested);
    }
    if (config_.trigger_mode == TriggerMode::kHardware) {
      log().warn("hardware trigger (", config_.trigger_source,
                 "): this path is NOT exercised by avs's tests (the Aravis fake camera only "
                 "free-runs); frames arrive only when the projector triggers");
    }
  }

  void on_activate() override {
    // Samples nobody holds any more let go of their buffers before and while next() waits,
    // which then returns them to the stream (capture thread).
    camera_->set_release_hook([this] {
      pattern_samples_.release_unused();
      raw_samples_.release_unused();
    });
    camera_->start();
    stop_ = false;
    thread_ = std::thread([this] { capture_loop(); });
  }

  void on_deactivate() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    camera_->stop();
    const SequencerStats s = sequencer_stats();
    const StreamCounters c = camera_->counters();
    log().info(received_.load(), " frames received, ", incomplete_.load(), " incomplete, ",
               s.labelled, " labelled, ", s.missing_ids, " missing ids, ", s.gaps, " gaps, ",
               s.locks, " locks, ", s.verify_failures, " pair mismatches; stream: ", c.underruns,
               " underruns, ", c.resent_packets, " resent packets");
  }

  /// The live parameters: exposure and gain are written to the camera at once (a refusal names
  /// what the camera allows and changes nothing); the sequencer's thresholds apply from the
  /// next frame; the /camera/image_raw rate from the next frame too.
  void on_parameters_changed(const runtime::ParameterValues& values,
                             const std::vector<std::string>& changed) override {
    const CameraConfig next = params().make(values);
    const auto is_changed = [&](const char* name) {
      return std::find(changed.begin(), changed.end(), name) != changed.end();
    };
    if (is_changed("exposure_time_us") || is_changed("gain")) {
      camera_->set_exposure_and_gain(is_changed("exposure_time_us") ? next.exposure_time_us : 0,
                                     is_changed("gain") ? next.gain : -1);
    }
    image_raw_rate_hz_ = next.image_raw_rate_hz;
    std::lock_guard lock(mutex_);  // the capture thread pushes frames under it
    sequencer_.retune(next.sequencer);
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    const SequencerStats s = sequencer_stats();
    const StreamCounters c = camera_->counters();
    double rate = 0;
    {
      std::lock_guard lock(mutex_);
      rate = rate_hz_;
    }
    const auto text = [](auto v) { return std::to_string(v); };
    return {{"frames_received", text(received_.load())},
            {"frames_incomplete", text(incomplete_.load())},
            {"frames_labelled", text(s.labelled)},
            {"missing_frame_ids", text(s.missing_ids)},
            {"gaps", text(s.gaps)},
            {"duplicates", text(s.duplicates)},
            {"late_frames", text(s.late_frames)},
            {"restarts", text(s.restarts)},
            {"locks", text(s.locks)},
            {"lock_losses", text(s.lock_losses)},
            {"pair_mismatches", text(s.verify_failures)},
            {"pairs_unverified", text(s.unverified_pairs)},
            {"dropped_not_locked", text(s.dropped_not_locked)},
            {"dropped_unpaired", text(s.dropped_unpaired)},
            {"locked", s.locks > s.lock_losses ? "true" : "false"},
            {"resent_packets", text(c.resent_packets)},
            {"missing_packets", text(c.missing_packets)},
            {"underruns", text(c.underruns)},
            {"stream_failures", text(c.failures)},
            {"frame_rate_hz", text(rate)},
            rejected_.diagnostic()};
  }

 private:
  /// A frame the sequencer holds (its buffer stays out of the pool meanwhile).
  struct Held {
    std::uint64_t token = 0;
    CapturedFrame frame;
    runtime::Time stamp;
  };

  static CameraConfig make_config(ComponentContext& ctx) {
    CameraConfig c = params().make(ctx.parameters());
    c.sequencer.frame_period_s = 1.0 / c.frame_rate_hz;
    return c;
  }

  SequencerStats sequencer_stats() const {
    std::lock_guard lock(mutex_);
    return sequencer_.stats();
  }

  void capture_loop() {
    const auto timeout = std::chrono::milliseconds(config_.buffer_timeout_ms);
    while (!stop_) {
      std::optional<CapturedFrame> frame = camera_->next(timeout);
      if (!frame) continue;
      try {
        on_buffer(std::move(*frame));
      } catch (const std::exception& e) {
        log().error("capture: ", e.what());
      }
    }
    std::lock_guard lock(mutex_);
    publish_released(sequencer_.flush());
  }

  void on_buffer(CapturedFrame f) {
    ++received_;
    update_rate(f.host_timestamp_ns);
    if (!f.complete) {
      ++incomplete_;
      rejected_.reject("frame id " + std::to_string(f.frame_id) + ": " + f.status);
      return;
    }
    if (f.width != expected_width_ || f.height != expected_height_) {
      rejected_.reject("frame id " + std::to_string(f.frame_id) + ": " + std::to_string(f.width) +
                       "x" + std::to_string(f.height) + ", configured " +
                       std::to_string(expected_width_) + "x" + std::to_string(expected_height_));
      return;
    }
    const runtime::Time stamp = stamp_of(f);
    publish_raw(f, stamp);
    CameraFrame input;
    input.frame_id = f.frame_id;
    // Timestamps order the frames; a camera without a clock (0) gets the host's.
    input.timestamp_ns = f.camera_timestamp_ns != 0 ? f.camera_timestamp_ns : f.host_timestamp_ns;
    input.image = {f.data, f.width, f.height, f.stride};
    input.token = ++token_;
    std::lock_guard lock(mutex_);
    Held* slot = free_slot();
    slot->token = input.token;
    slot->stamp = stamp;
    slot->frame = std::move(f);
    publish_released(sequencer_.push(input));
  }

  Held* free_slot() {
    for (Held& h : held_) {
      if (h.token == 0) return &h;
    }
    throw std::logic_error("camera: the sequencer holds more frames than it may");
  }

  void publish_released(const Released& r) {
    for (int i = 0; i < r.count; ++i) {
      const ReleasedFrame& rf = r.frames[static_cast<std::size_t>(i)];
      for (Held& h : held_) {
        if (h.token != rf.token) continue;
        if (rf.reason == DropReason::kNone) publish_pattern(h, rf.label);
        h.token = 0;
        h.frame = CapturedFrame{};  // the buffer returns to the pool unless published
      }
    }
  }

  runtime::Time stamp_of(const CapturedFrame& f) {
    switch (config_.stamp_source) {
      case StampSource::kCamera:
        return {f.camera_timestamp_ns};
      case StampSource::kHostArrival:
        return {f.host_timestamp_ns};
      case StampSource::kHostMapped:
        break;
    }
    if (f.camera_timestamp_ns == 0) return {f.host_timestamp_ns};
    const std::int64_t offset = f.host_timestamp_ns - f.camera_timestamp_ns;
    if (!have_offset_ || offset < offset_ns_) offset_ns_ = offset;
    have_offset_ = true;
    return {f.camera_timestamp_ns + offset_ns_};
  }

  void update_rate(std::int64_t host_ns) {
    ++rate_frames_;
    if (rate_window_start_ns_ == 0) rate_window_start_ns_ = host_ns;
    const std::int64_t span = host_ns - rate_window_start_ns_;
    if (span >= 1'000'000'000) {
      std::lock_guard lock(mutex_);
      rate_hz_ = static_cast<double>(rate_frames_) * 1e9 / static_cast<double>(span);
      rate_frames_ = 0;
      rate_window_start_ns_ = host_ns;
    }
  }

  template <class Image>
  void fill_image(Image& image, const CapturedFrame& f, runtime::Time stamp) const {
    runtime::to_ros_time(stamp, image.header.stamp);
    runtime::set_string(image.header.frame_id, frame_id_);
    runtime::set_string(image.encoding, "mono8");
    image.width = static_cast<std::uint32_t>(f.width);
    image.height = static_cast<std::uint32_t>(f.height);
    image.step = static_cast<std::uint32_t>(f.stride);
    image.is_bigendian = 0;
  }

  void publish_raw(const CapturedFrame& f, runtime::Time stamp) {
    const double rate_hz = image_raw_rate_hz_.load();
    if (rate_hz <= 0) return;
    const auto min_step_ns = static_cast<std::int64_t>(1e9 / rate_hz);
    if (last_raw_ns_ != 0 && f.host_timestamp_ns - last_raw_ns_ < min_step_ns) return;
    last_raw_ns_ = f.host_timestamp_ns;
    auto m = raw_samples_.lend(f.data, f.size, f.lease);  // every field set below
    fill_image(*m, f, stamp);
    image_raw_.publish(std::move(m));
  }

  void publish_pattern(const Held& h, const FrameLabel& label) {
    const CapturedFrame& f = h.frame;
    auto m = pattern_samples_.lend(f.data, f.size, f.lease);  // every field set below
    runtime::to_ros_time(h.stamp, m->header.stamp);
    runtime::set_string(m->header.frame_id, frame_id_);
    fill_image(m->image, f, h.stamp);
    m->bit_index = static_cast<std::uint8_t>(label.bit_index);
    m->bit_count = static_cast<std::uint8_t>(config_.sequencer.bit_count);
    m->positive = label.polarity == decode::Polarity::kPositive;
    m->cycle = static_cast<std::uint32_t>(label.cycle);
    // pan_rad / tilt_rad stay 0: the camera does not know the head (/head/joint_states does).
    pattern_.publish(std::move(m));
  }

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  runtime::Publisher<msgs::sensor_msgs::Image> image_raw_;
  CameraConfig config_;  ///< as started; the live parameters are kept apart (below)
  std::atomic<double> image_raw_rate_hz_{config_.image_raw_rate_hz};  ///< live
  std::string frame_id_;
  int expected_width_ = config_.width;
  int expected_height_ = config_.height;
  std::unique_ptr<AravisCamera> camera_;

  // Capture thread only.
  /// The published samples, kept with their strings; their image bytes are the camera's
  /// buffers, lent (no copy, no allocation per frame).
  runtime::LentSamplePool<msgs::avs_msgs::PatternFrame> pattern_samples_{
      [](msgs::avs_msgs::PatternFrame& p) -> dds_sequence_uint8& { return p.image.data; }};
  runtime::LentSamplePool<msgs::sensor_msgs::Image> raw_samples_{
      [](msgs::sensor_msgs::Image& i) -> dds_sequence_uint8& { return i.data; }};
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::uint64_t token_ = 0;
  bool have_offset_ = false;
  std::int64_t offset_ns_ = 0;
  std::int64_t last_raw_ns_ = 0;
  std::int64_t rate_frames_ = 0;
  std::int64_t rate_window_start_ns_ = 0;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> incomplete_{0};

  // Shared with diagnostic_values() (the container's diagnostics timer).
  mutable std::mutex mutex_;
  PatternSequencer sequencer_;
  std::array<Held, 4> held_;
  double rate_hz_ = 0;
  runtime::SampleRejections rejected_;
};

AVS_REGISTER_COMPONENT(CameraComponent);

}  // namespace avs::camera
