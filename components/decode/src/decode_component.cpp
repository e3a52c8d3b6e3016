// decode: the depth sensor of the paper's section 4 as a component. Pattern frames
// (/camera/pattern, mono8 + bit index, polarity, cycle) go into one RollingDecoder, placed by
// their bit index and cycle counter (never by arrival); every completed positive/negative pair
// gives a depth map (Eqs. 2-4, 500 Hz from 1000 fps) on /depth/image (32FC1, metres, NaN
// invalid, stamp of the newest frame used), optionally a PointCloud2 on /depth/points, the
// map's data age on /depth/info and the camera model in force on /depth/camera_info (both with
// the same stamp; camera_info is also latched, transient-local, from activation on) and the
// wall-clock processing time of the pair on /timing. Dropped and out-of-order frames are counted
// by the decoder and reported on /diagnostics; a malformed frame is rejected with its reason
// (counted as rejected_samples), never stops the container.
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>

#include "avs/decode/calibration_yaml.hpp"
#include "avs/decode/rolling_decoder.hpp"
#include "avs/geometry/frames.hpp"
#include "avs/msg/camera_info.hpp"
#include "avs/msg/convert.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::decode {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

namespace {

/// The geometry from `calibration_file` (empty: default_sensor_geometry()), with the code
/// layout parameters that are set (non-zero / non-negative) applied over the file's.
SensorGeometry make_geometry(ComponentContext& ctx) {
  const auto file = ctx.param<std::string>("calibration_file");
  SensorGeometry g = file.empty() ? default_sensor_geometry() : load_sensor_geometry_yaml(file);
  if (const int n = ctx.param<int>("bit_count"); n > 0) g.layout.bit_count = n;
  if (const int codes = ctx.param<int>("code_count"); codes > 0) g.layout.code_count = codes;
  if (const int rows = ctx.param<int>("rows_per_code"); rows > 0) g.layout.rows_per_code = rows;
  if (const int first = ctx.param<int>("first_row"); first >= 0) g.layout.first_row = first;
  const CodeLayout& l = g.layout;
  if (l.code_count > (1 << l.bit_count) || l.first_row + l.used_rows() > g.projector.height) {
    throw std::invalid_argument("decode: code layout of " + std::to_string(l.code_count) +
                                " codes x " + std::to_string(l.rows_per_code) + " rows from row " +
                                std::to_string(l.first_row) + " does not fit " +
                                std::to_string(l.bit_count) + " bits and the projector's " +
                                std::to_string(g.projector.height) + " rows" +
                                (file.empty() ? std::string() : " (calibration " + file + ")"));
  }
  return g;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

class DecodeComponent final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    // Frames in: a gap costs a whole cycle of depth (the missing bit is invalid until it is
    // measured again: n depth maps) and the matcher's re-acquisition, while catching up 16
    // frames costs about 8 ms at 0.5 ms a frame. So decode keeps the newest 16 (the camera
    // component's stream buffers, 32, are behind them) before it skips (docs/realtime.md).
    runtime::QosProfile keep_last_16;
    keep_last_16.depth = 16;
    runtime::QosProfile points_qos;
    points_qos.reliability = runtime::Reliability::best_effort;
    points_qos.depth = 2;
    runtime::QosProfile keep_last_100;
    keep_last_100.depth = 100;
    return {
        .type = "decode",
        .description =
            "Gray-code depth (section 4): /camera/pattern frames -> rolling decode with code "
            "correction and ray x plane triangulation -> /depth/image (32FC1 m) per pair, "
            "/depth/camera_info, /depth/info, optional /depth/points, /timing",
        .parameters = params().specs_with(
            {ParamSpec::integer("bit_count", 0, 0, 15, "",
                                "n code bits; 0: from the calibration (default 9)"),
             ParamSpec::integer("code_count", 0, 0, 32768, "",
                                "codes used; 0: from the calibration (default 265)"),
             ParamSpec::integer("rows_per_code", 0, 0, 4096, "px",
                                "projector rows per code; 0: from the calibration (default 4)"),
             ParamSpec::integer("first_row", -1, -1, 65535, "px",
                                "projector row of code 0; -1: from the calibration (default 40)"),
             ParamSpec::string("calibration_file", "",
                               "sensor geometry YAML (docs/decode.md); empty: the paper's "
                               "sensor, default_sensor_geometry()"),
             ParamSpec::string("mode", "rolling",
                               "rolling: a depth map per pair (500 Hz); full_cycle: one per "
                               "complete 2n-frame cycle, no correction",
                               {"rolling", "full_cycle"}),
             ParamSpec::boolean("publish_points", false,
                                "also publish /depth/points (organised XYZ float32)"),
             ParamSpec::string("frame_id", geometry::frame::kCameraOptical,
                               "header.frame_id of depth and points (the /tf frame)")}),
        .publishes = {runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image", keep_last_4),
                      runtime::port<msgs::sensor_msgs::PointCloud2>("points", "/depth/points",
                                                                    points_qos),
                      runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing",
                                                                 keep_last_100),
                      runtime::port<msgs::avs_msgs::DepthInfo>("info", "/depth/info", keep_last_4),
                      runtime::port<msgs::sensor_msgs::CameraInfo>(
                          "camera_info", "/depth/camera_info", msg::camera_info_qos())},
        .subscribes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                                   keep_last_16)},
        .default_mismatches = [] { return params().default_mismatches(); }};
  }

  /// Parameters bound to DecoderConfig (its defaults are the parameters').
  static const runtime::ConfigParams<DecoderConfig>& params() {
    static const auto p =
        runtime::ConfigParams<DecoderConfig>()
            .integer("threshold_psi", AVS_FIELD(threshold_psi), 0, 255, "",
                     "Eq. 2: |I_pos - I_neg| must exceed psi (8-bit units)")
            .live()
            .boolean("code_correction", AVS_FIELD(code_correction),
                     "Algorithm 1 (section 4.4); ignored in full_cycle mode")
            .live()
            .integer("max_bit_age_pairs", AVS_FIELD(max_bit_age_pairs), 0, 1000, "",
                     "use a bit while at most this many pairs old; 0: n (rolling only; 2n rides "
                     "a static scene through a drop)")
            .live()
            .real("min_depth_m", AVS_FIELD(min_depth_m), 0.0, 1000.0, "m", "nearer depths are NaN")
            .live()
            .real("max_depth_m", AVS_FIELD(max_depth_m), 0.0, 1000.0, "m", "farther depths are NaN")
            .live()
            .choice("triangulation", AVS_FIELD(triangulation),
                    std::vector<std::pair<std::string, TriangulationMethod>>{
                        {"table", TriangulationMethod::kRayPlaneTable},
                        {"reference", TriangulationMethod::kReferenceSolve}},
                    "table: ray x plane look-up; reference: per-pixel 3x3 solve of Eq. 4 (slow, "
                    "for comparison)")
            .integer("subcode_half_window", AVS_FIELD(subcode_half_window), 0, 16, "px",
                     "sub-code refinement: fit the codes of 2h+1 rows of each column, "
                     "triangulate the fitted fractional code; 0: off (code centres). Table "
                     "triangulation only; about 0.05 ms per update (avs bench decode)")
            .integer("subcode_max_jump", AVS_FIELD(subcode_max_jump), 0, 1000, "",
                     "codes per row that mark a discontinuity (the pixel keeps its plain code)")
            .integer("subcode_steps", AVS_FIELD(subcode_steps), 1, 256, "",
                     "sub-code planes per code (the fitted code's resolution)");
    return p;
  }

  explicit DecodeComponent(ComponentContext& ctx)
      : Component(ctx),
        depth_(ctx.publisher<msgs::sensor_msgs::Image>("depth")),
        points_(ctx.publisher<msgs::sensor_msgs::PointCloud2>("points")),
        timing_(ctx.publisher<msgs::avs_msgs::StageTiming>("timing")),
        info_(ctx.publisher<msgs::avs_msgs::DepthInfo>("info")),
        camera_info_(ctx.publisher<msgs::sensor_msgs::CameraInfo>("camera_info")),
        full_cycle_(ctx.param<std::string>("mode") == "full_cycle"),
        publish_points_(ctx.param<bool>("publish_points")),
        frame_id_(ctx.param<std::string>("frame_id")),
        decoder_(make_config(ctx.parameters(), make_geometry(ctx))),
        rejected_(ctx.log(), "/camera/pattern frame") {
    const SensorGeometry& g = decoder_.config().geometry;
    width_ = g.camera.width;
    height_ = g.camera.height;
    bit_count_ = g.layout.bit_count;
    ctx.subscribe<msgs::avs_msgs::PatternFrame>(
        "pattern", [this](runtime::SamplePtr<msgs::avs_msgs::PatternFrame> m) { on_frame(*m); });
    log().info(full_cycle_ ? "full-cycle" : "rolling", " decode of ", width_, "x", height_,
               " frames, ", bit_count_, " bits, ", g.layout.code_count, " codes x ",
               g.layout.rows_per_code, " rows from row ", g.layout.first_row, ", psi ",
               decoder_.config().threshold_psi, ", correction ",
               decoder_.config().code_correction ? "on" : "off", ", sub-code half window ",
               decoder_.config().subcode_half_window);
  }

  void on_activate() override { publish_camera_info(nullptr); }

  void on_deactivate() override {
    const DecoderStats s = decoder_.stats();
    log().info(s.frames_received, " frames, ", s.pairs_decoded, " pairs, ", published_,
               " depth maps; dropped ", s.dropped_frames, ", out of order ", s.out_of_order_frames,
               ", incomplete pairs ", s.incomplete_pairs, ", source restarts ", s.source_restarts);
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    std::lock_guard lock(mutex_);
    const DecoderStats& s = reported_;
    return {{"frames_received", std::to_string(s.frames_received)},
            {"pairs_decoded", std::to_string(s.pairs_decoded)},
            {"depth_published", std::to_string(published_)},
            {"dropped_frames", std::to_string(s.dropped_frames)},
            {"out_of_order_frames", std::to_string(s.out_of_order_frames)},
            {"incomplete_pairs", std::to_string(s.incomplete_pairs)},
            {"source_restarts", std::to_string(s.source_restarts)},
            {"processing_ms_mean",
             std::to_string(published_ > 0 ? total_ms_ / static_cast<double>(published_) : 0.0)},
            {"processing_ms_max", std::to_string(max_ms_)},
            {"processing_ms_last", std::to_string(last_ms_)},
            rejected_.diagnostic()};
  }

  /// The live parameters (threshold, correction, bit age, depth window) take effect from the
  /// next pair on; the bits kept so far stay.
  void on_parameters_changed(const runtime::ParameterValues& values,
                             const std::vector<std::string>& /*changed*/) override {
    decoder_.retune(make_config(values, decoder_.config().geometry));
  }

  /// Decoder statistics (for tests; same numbers as diagnostic_values()).
  DecoderStats stats() const {
    std::lock_guard lock(mutex_);
    return reported_;
  }

 private:
  static DecoderConfig make_config(const runtime::ParameterValues& values,
                                   SensorGeometry geometry) {
    DecoderConfig c = params().make(values);
    c.geometry = std::move(geometry);
    if (!(c.min_depth_m < c.max_depth_m)) {
      throw std::invalid_argument("decode: min_depth_m must be below max_depth_m");
    }
    if (values.get<std::string>("mode") == "full_cycle") {
      // Section 4.1: one cycle's bits only (a bit older than the cycle invalidates the map,
      // see RollingDecoder::fresh_mask), no correction.
      c.code_correction = false;
      c.max_bit_age_pairs = c.geometry.layout.bit_count;
    }
    return c;
  }

  /// Why the frame cannot be decoded, or empty.
  std::string frame_problem(const msgs::avs_msgs::PatternFrame& m) const {
    const auto& image = m.image;
    const std::string_view encoding = runtime::get_string(image.encoding);
    std::string problem;
    if (encoding != "mono8" && encoding != "8UC1") {
      problem = "encoding '" + std::string(encoding) + "', expected mono8";
    } else if (static_cast<int>(image.width) != width_ ||
               static_cast<int>(image.height) != height_) {
      problem = "size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                ", the calibration's camera is " + std::to_string(width_) + "x" +
                std::to_string(height_);
    } else if (image.step < image.width ||
               static_cast<std::uint64_t>(image.step) * image.height > image.data._length) {
      problem = "step " + std::to_string(image.step) + " with " +
                std::to_string(image.data._length) + " bytes of data";
    } else if (m.bit_count != bit_count_) {
      problem = "bit_count " + std::to_string(m.bit_count) + ", the decoder uses " +
                std::to_string(bit_count_) + " (parameter bit_count / calibration code_layout)";
    } else if (m.bit_index >= bit_count_) {
      problem = "bit_index " + std::to_string(m.bit_index) + ", expected 0.." +
                std::to_string(bit_count_ - 1);
    }
    if (problem.empty()) return {};
    return "pattern frame (cycle " + std::to_string(m.cycle) + ", bit " +
           std::to_string(m.bit_index) + ") has " + problem;
  }

  void on_frame(const msgs::avs_msgs::PatternFrame& m) {
    const auto start = std::chrono::steady_clock::now();
    if (std::string problem = frame_problem(m); !problem.empty()) {
      rejected_.reject(problem);
      return;
    }
    PatternFrame frame;
    frame.image = {m.image.data._buffer, width_, height_,
                   static_cast<std::ptrdiff_t>(m.image.step)};
    frame.bit_index = m.bit_index;
    frame.polarity = m.positive ? Polarity::kPositive : Polarity::kNegative;
    frame.cycle = m.cycle;

    // Frame period for the data age: a negative and the positive just before it (same bit,
    // same cycle) are one frame apart.
    const double stamp_s = runtime::from_ros_time(m.header.stamp).seconds();
    if (!m.positive && previous_positive_ && previous_cycle_ == m.cycle &&
        previous_bit_ == m.bit_index && stamp_s > previous_stamp_s_) {
      frame_period_s_ = stamp_s - previous_stamp_s_;
    }
    previous_positive_ = m.positive;
    previous_cycle_ = m.cycle;
    previous_bit_ = m.bit_index;
    previous_stamp_s_ = stamp_s;

    const DecoderStats before = decoder_.stats();
    // A negative may complete a pair: decode straight into the outgoing message (no copy).
    const bool publishable =
        !m.positive && (!full_cycle_ || m.bit_index == static_cast<std::uint8_t>(bit_count_ - 1));
    std::shared_ptr<msgs::sensor_msgs::Image> image;
    DecodeResult result;
    if (publishable) {
      image = depth_.loan();
      runtime::resize_sequence(image->data, static_cast<std::uint32_t>(4 * width_ * height_));
      result =
          decoder_.push_frame(frame, std::span<float>(reinterpret_cast<float*>(image->data._buffer),
                                                      static_cast<std::size_t>(width_) * height_));
    } else {
      result = decoder_.push_frame(frame);
    }
    report_losses(before, result.stats, m);
    if (!publishable || !result.depth_updated) {
      pending_ms_ += ms_since(start);  // e.g. the positive's share of the pair's time
      std::lock_guard lock(mutex_);
      reported_ = result.stats;
      return;
    }

    image->header.stamp = m.header.stamp;  // the newest frame used
    runtime::set_string(image->header.frame_id, frame_id_);
    runtime::set_string(image->encoding, "32FC1");
    image->width = static_cast<std::uint32_t>(width_);
    image->height = static_cast<std::uint32_t>(height_);
    image->step = static_cast<std::uint32_t>(4 * width_);
    image->is_bigendian = 0;
    if (publish_points_) publish_points(*image);
    // The data age before the image it describes (subscribers match them by stamp). A pair's
    // information is effective_age_pairs pairs (2 frames each) plus half a frame (the pair's
    // mid-time) older than the newest frame (docs/decode.md).
    if (std::isfinite(result.effective_age_pairs) && frame_period_s_ > 0.0) {
      auto info = info_.loan();
      info->header.stamp = m.header.stamp;
      runtime::set_string(info->header.frame_id, frame_id_);
      info->effective_age_pairs = result.effective_age_pairs;
      info->frame_period_s = frame_period_s_;
      info->data_age_s = (2.0 * result.effective_age_pairs + 0.5) * frame_period_s_;
      info_.publish(std::move(info));
    }
    publish_camera_info(&m.header.stamp);
    depth_.publish(std::move(image));

    const double ms = pending_ms_ + ms_since(start);
    pending_ms_ = 0;
    auto timing = timing_.loan();
    timing->header.stamp = m.header.stamp;
    runtime::set_string(timing->header.frame_id, frame_id_);
    runtime::set_string(timing->stage, "decode");
    timing->processing_ms = ms;
    timing_.publish(std::move(timing));

    std::lock_guard lock(mutex_);
    reported_ = result.stats;
    ++published_;
    total_ms_ += ms;
    max_ms_ = std::max(max_ms_, ms);
    last_ms_ = ms;
  }

  /// Logs the first few losses (and every 1000th after); the counts go to /diagnostics.
  void report_losses(const DecoderStats& before, const DecoderStats& after,
                     const msgs::avs_msgs::PatternFrame& m) {
    if (after.source_restarts != before.source_restarts) {
      log().warn("frame cycle ", m.cycle, " bit ", int{m.bit_index},
                 ": more than two cycles behind the newest frame, so the source started again "
                 "(restart ",
                 after.source_restarts, "); decoding starts over with it");
    }
    const std::int64_t events = (after.dropped_frames - before.dropped_frames) +
                                (after.out_of_order_frames - before.out_of_order_frames);
    if (events == 0) return;
    ++loss_events_;
    if (loss_events_ <= 5 || loss_events_ % 1000 == 0) {
      log().warn("frame cycle ", m.cycle, " bit ", int{m.bit_index},
                 m.positive ? " positive" : " negative", ": ",
                 after.dropped_frames - before.dropped_frames, " dropped before it, ",
                 after.out_of_order_frames - before.out_of_order_frames,
                 " out of order (totals: dropped ", after.dropped_frames, ", out of order ",
                 after.out_of_order_frames, ")");
    }
  }

  /// The camera model in force (the calibration's camera) as sensor_msgs/CameraInfo, with the
  /// stamp of the depth image it goes with (none: zero, the latched copy at activation). The
  /// model never changes while the component runs (retune keeps the geometry), so the copies
  /// with an image are publish_unchanged: not serialised for the latched history when no
  /// other process listens (no DDS allocation per depth map).
  void publish_camera_info(const msgs::builtin_interfaces::Time* stamp) {
    auto info = camera_info_.loan();
    msg::to_camera_info(decoder_.config().geometry.camera, *info);
    info->header.stamp = stamp != nullptr ? *stamp : msgs::builtin_interfaces::Time{};
    runtime::set_string(info->header.frame_id, frame_id_);
    if (stamp != nullptr) {
      camera_info_.publish_unchanged(std::move(info));
    } else {
      camera_info_.publish(std::move(info));
    }
  }

  /// Organised XYZ cloud (float32 x, y, z; NaN invalid) from the depth just computed:
  /// X = z x, Y = z y, Z = z with the undistorted ray (x, y, 1) of each pixel.
  void publish_points(const msgs::sensor_msgs::Image& depth_image) {
    auto cloud = points_.loan();
    cloud->header.stamp = depth_image.header.stamp;
    runtime::set_string(cloud->header.frame_id, frame_id_);
    cloud->height = static_cast<std::uint32_t>(height_);
    cloud->width = static_cast<std::uint32_t>(width_);
    msg::set_xyz_fields(*cloud);
    cloud->row_step = static_cast<std::uint32_t>(12 * width_);
    cloud->is_dense = false;
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    runtime::resize_sequence(cloud->data, static_cast<std::uint32_t>(12 * pixels));
    auto* xyz = reinterpret_cast<float*>(cloud->data._buffer);
    const auto* z = reinterpret_cast<const float*>(depth_image.data._buffer);
    const float* rx = decoder_.table().ray_x();
    const float* ry = decoder_.table().ray_y();
    for (std::size_t i = 0; i < pixels; ++i) {
      xyz[3 * i] = z[i] * rx[i];
      xyz[3 * i + 1] = z[i] * ry[i];
      xyz[3 * i + 2] = z[i];
    }
    points_.publish(std::move(cloud));
  }

  runtime::Publisher<msgs::sensor_msgs::Image> depth_;
  runtime::Publisher<msgs::sensor_msgs::PointCloud2> points_;
  runtime::Publisher<msgs::avs_msgs::StageTiming> timing_;
  runtime::Publisher<msgs::avs_msgs::DepthInfo> info_;
  runtime::Publisher<msgs::sensor_msgs::CameraInfo> camera_info_;
  bool full_cycle_;
  double frame_period_s_ = 0.0;
  double previous_stamp_s_ = 0.0;
  bool previous_positive_ = false;
  std::uint32_t previous_cycle_ = 0;
  std::uint8_t previous_bit_ = 0;
  bool publish_points_;
  std::string frame_id_;
  RollingDecoder decoder_;
  runtime::SampleRejections rejected_;
  int width_ = 0;
  int height_ = 0;
  int bit_count_ = 0;
  double pending_ms_ = 0;  ///< time spent on frames since the last depth map
  std::int64_t loss_events_ = 0;

  // Read by diagnostic_values() on the container's diagnostics timer.
  mutable std::mutex mutex_;
  DecoderStats reported_;
  std::int64_t published_ = 0;
  double total_ms_ = 0;
  double max_ms_ = 0;
  double last_ms_ = 0;
};

AVS_REGISTER_COMPONENT(DecodeComponent);

}  // namespace avs::decode
