// The `decode` component in one container, sim-time lockstep: a test source publishes the
// Gray-code frames of a plane at 1.0 m facing the sensor (decode::render_plane, the same
// geometry the decoder uses, noise and a shadowed box) at 1000 fps; a recorder checks every
// /depth/image against the plane's true depth, its stamp against the frames, the 500 Hz
// cadence, /timing, and what dropped / out-of-order frames do.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "avs/decode/synthetic_plane.hpp"
#include "avs/graph/graph.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/parameter_messages.hpp"
#include "avs/sim/simulator.hpp"
#include "avs/testing/diagnostics.hpp"
#include "avs/testing/lockstep_graph.hpp"
#include "avs/testing/test_domain.hpp"
#ifdef AVS_PROGRAM
#include <regex>
#include <sstream>
#include <thread>

#include "avs_program.hpp"
#endif

namespace avs::decode {
namespace {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

constexpr int kBits = 9;
constexpr int kFramesPerCycle = 2 * kBits;

/// The scene both the source and the checks use: plane at 1.0 m, noise sigma 3, a shadow. Low
/// contrast (the projector adds 40 instead of 180, noise sigma 6): how many pixels pass Eq. 2
/// then depends on psi (the run-time parameter test).
const SyntheticScene& plane_scene(bool low_contrast = false) {
  static const auto render = [](bool low) {
    PlaneSceneConfig c;
    c.plane_depth_m = 1.0;
    c.noise_sigma = low ? 6.0 : 3.0;
    c.amplitude = low ? 40.0 : c.amplitude;
    c.seed = 2024;
    c.shadow_x0 = 200;
    c.shadow_x1 = 280;
    c.shadow_y0 = 150;
    c.shadow_y1 = 250;
    return render_plane(default_sensor_geometry(), c);
  };
  static const SyntheticScene scene = render(false);
  if (!low_contrast) return scene;
  static const SyntheticScene low = render(true);
  return low;
}

/// What the recorder compares with: true depth, directly lit pixels, shadowed pixels.
struct Truth {
  std::vector<float> depth_m;
  std::vector<std::uint8_t> lit;       ///< lit by a coded projector row, not shadowed
  std::vector<std::uint8_t> shadowed;  ///< a surface the projector does not light
};

const Truth& plane_truth(bool low_contrast = false) {
  static const auto make = [](const SyntheticScene& scene) {
    Truth t;
    t.depth_m = scene.true_depth_m;
    t.shadowed = scene.shadowed;
    t.lit.resize(scene.lit.size());
    for (std::size_t i = 0; i < t.lit.size(); ++i) t.lit[i] = scene.lit[i] && !scene.shadowed[i];
    return t;
  };
  static const Truth truth = make(plane_scene(false));
  if (!low_contrast) return truth;
  static const Truth low = make(plane_scene(true));
  return low;
}

/// The truth the current test's source renders (set by the source before its first frame).
const Truth* current_truth = nullptr;

std::set<std::int64_t> as_set(const std::vector<double>& v) {
  std::set<std::int64_t> s;
  for (double x : v) s.insert(static_cast<std::int64_t>(x));
  return s;
}

/// Publishes frame f (bit (f mod 2n) / 2, positive when f is even, cycle f / 2n) every
/// 1 ms, stamped with the clock; skips `drop_frames` and sends each of `swap_frames` after
/// its successor.
class TestPlanePatterns final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {.type = "test_plane_patterns",
            .description = "tests: Gray-code frames of a plane at 1 m, 1000 fps",
            .parameters = {ParamSpec::real_list("drop_frames", {}, "", "frame numbers never sent"),
                           ParamSpec::real_list("swap_frames", {}, "",
                                                "frame numbers sent after the next one"),
                           ParamSpec::boolean("low_contrast", false,
                                              "the projector adds 40, not 180; noise sigma 6")},
            .publishes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                                      keep_last_4)},
            .subscribes = {}};
  }

  explicit TestPlanePatterns(ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        drop_(as_set(ctx.param<std::vector<double>>("drop_frames"))),
        swap_(as_set(ctx.param<std::vector<double>>("swap_frames"))),
        low_contrast_(ctx.param<bool>("low_contrast")) {}

  void on_activate() override {
    current_truth = &plane_truth(low_contrast_);
    context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  /// Stamp (ns) of every frame number made so far, sent or not.
  std::vector<std::int64_t> stamps_ns;

 private:
  void tick() {
    const std::int64_t f = next_++;
    const runtime::Time now = context().now();
    stamps_ns.push_back(now.ns);
    auto frame = make_frame(f, now);
    if (held_) {  // the swapped frame goes after this one
      if (!drop_.contains(f)) pattern_.publish(frame);
      pattern_.publish(std::move(held_));
      held_.reset();
      return;
    }
    if (drop_.contains(f)) return;
    if (swap_.contains(f)) {
      held_ = std::move(frame);
      return;
    }
    pattern_.publish(std::move(frame));
  }

  std::shared_ptr<const msgs::avs_msgs::PatternFrame> make_frame(std::int64_t f,
                                                                 runtime::Time now) {
    const SyntheticScene& scene = plane_scene(low_contrast_);
    auto m = runtime::make_sample<msgs::avs_msgs::PatternFrame>();
    runtime::to_ros_time(now, m->header.stamp);
    runtime::set_string(m->header.frame_id, "camera");
    const int slot = static_cast<int>(f % kFramesPerCycle);
    m->bit_index = static_cast<std::uint8_t>(slot / 2);
    m->bit_count = kBits;
    m->positive = slot % 2 == 0;
    m->cycle = static_cast<std::uint32_t>(f / kFramesPerCycle);
    auto& image = m->image;
    image.header.stamp = m->header.stamp;
    runtime::set_string(image.header.frame_id, "camera");
    runtime::set_string(image.encoding, "mono8");
    image.width = static_cast<std::uint32_t>(scene.width);
    image.height = static_cast<std::uint32_t>(scene.height);
    image.step = image.width;
    const auto& pixels = scene.frames[static_cast<std::size_t>(slot)];
    runtime::resize_sequence(image.data, static_cast<std::uint32_t>(pixels.size()));
    std::copy(pixels.begin(), pixels.end(), image.data._buffer);
    return m;
  }

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  std::set<std::int64_t> drop_;
  std::set<std::int64_t> swap_;
  bool low_contrast_;
  std::int64_t next_ = 0;
  std::shared_ptr<const msgs::avs_msgs::PatternFrame> held_;
};

/// The simulator (avs_sim_core) instead of the analytic plane: its renderer draws a plane 1.0 m
/// in front of the camera (the head at rest, q = 0, looks along world +X; the camera sits 40 mm
/// in front of the tilt axis), and its ground truth is what the depth is compared with.
class TestSimPlanePatterns final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {.type = "test_sim_plane_patterns",
            .description = "tests: simulator frames of a plane 1 m in front of the camera",
            .parameters = {ParamSpec::real("plane_x_m", 1.04, 0.1, 100.0, "m",
                                           "plane's distance from the pan axis")},
            .publishes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                                      keep_last_4)},
            .subscribes = {}};
  }

  explicit TestSimPlanePatterns(ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        sim_(sim::SimulatorConfig{},
             sim::Scene{{sim::make_background_plane(ctx.param<double>("plane_x_m"))}}) {
    sim_.render(0, head_);  // ground truth of the (static) view
    const sim::Renderer& r = sim_.renderer();
    truth_.depth_m = r.depth_m();
    truth_.lit.resize(truth_.depth_m.size());
    truth_.shadowed.resize(truth_.depth_m.size());
    for (std::size_t i = 0; i < truth_.lit.size(); ++i) {
      truth_.lit[i] = r.code()[i] >= 0;
      truth_.shadowed[i] = r.object_index()[i] >= 0 && r.code()[i] < 0;
    }
  }

  void on_activate() override {
    current_truth = &truth_;
    context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  std::vector<std::int64_t> stamps_ns;
  const Truth& truth() const { return truth_; }

 private:
  void tick() {
    const runtime::Time now = context().now();
    stamps_ns.push_back(now.ns);
    const sim::SimFrame frame = sim_.render(next_++, head_);
    auto m = runtime::make_sample<msgs::avs_msgs::PatternFrame>();
    runtime::to_ros_time(now, m->header.stamp);
    runtime::set_string(m->header.frame_id, "camera");
    m->bit_index = static_cast<std::uint8_t>(frame.pattern.bit_index);
    m->bit_count = kBits;
    m->positive = frame.pattern.positive;
    m->cycle = frame.pattern.cycle;
    auto& image = m->image;
    image.header.stamp = m->header.stamp;
    runtime::set_string(image.header.frame_id, "camera");
    runtime::set_string(image.encoding, "mono8");
    image.width = static_cast<std::uint32_t>(frame.image.width);
    image.height = static_cast<std::uint32_t>(frame.image.height);
    image.step = image.width;
    runtime::resize_sequence(image.data, static_cast<std::uint32_t>(frame.image.pixels.size()));
    std::copy(frame.image.pixels.begin(), frame.image.pixels.end(), image.data._buffer);
    pattern_.publish(std::move(m));
  }

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  sim::Simulator sim_;
  sim::HeadState head_;
  Truth truth_;
  std::uint64_t next_ = 0;
};

/// Per depth image: stamp, and its agreement with the plane's true depth.
struct DepthRecord {
  std::int64_t stamp_ns = 0;
  std::int64_t valid = 0;  ///< finite pixels
  std::int64_t lit = 0;    ///< directly lit, not shadowed
  std::int64_t lit_valid = 0;
  std::int64_t shadow_valid = 0;
  std::int64_t far_off = 0;  ///< valid pixels more than 2 code steps (40 mm) off
  double rms_m = 0;          ///< over valid lit pixels
};

class TestDepthRecorder final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {.type = "test_depth_recorder",
            .description = "tests: checks /depth/image against the test plane",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image"),
                           runtime::port<msgs::sensor_msgs::PointCloud2>("points", "/depth/points"),
                           runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing"),
                           runtime::port<msgs::avs_msgs::DepthInfo>("info", "/depth/info")}};
  }

  explicit TestDepthRecorder(ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth(m); });
    ctx.subscribe<msgs::sensor_msgs::PointCloud2>(
        "points", [this](runtime::SamplePtr<msgs::sensor_msgs::PointCloud2> m) {
          points.push_back(m);
          if (points.size() > 2) points.erase(points.begin());
        });
    ctx.subscribe<msgs::avs_msgs::StageTiming>(
        "timing",
        [this](runtime::SamplePtr<msgs::avs_msgs::StageTiming> m) { timing.push_back(m); });
    ctx.subscribe<msgs::avs_msgs::DepthInfo>(
        "info", [this](runtime::SamplePtr<msgs::avs_msgs::DepthInfo> m) { info.push_back(m); });
  }

  std::vector<DepthRecord> depth;
  std::vector<std::string> encodings;
  runtime::SamplePtr<msgs::sensor_msgs::Image> last_depth;
  std::vector<runtime::SamplePtr<msgs::sensor_msgs::PointCloud2>> points;
  std::vector<runtime::SamplePtr<msgs::avs_msgs::StageTiming>> timing;
  std::vector<runtime::SamplePtr<msgs::avs_msgs::DepthInfo>> info;

 private:
  void on_depth(const runtime::SamplePtr<msgs::sensor_msgs::Image>& m) {
    ASSERT_NE(current_truth, nullptr);
    const Truth& truth = *current_truth;
    last_depth = m;
    encodings.emplace_back(runtime::get_string(m->encoding));
    DepthRecord r;
    r.stamp_ns = runtime::from_ros_time(m->header.stamp).ns;
    const auto* z = reinterpret_cast<const float*>(m->data._buffer);
    const std::size_t pixels = std::min<std::size_t>(m->data._length / 4, truth.lit.size());
    double sum = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
      const bool finite = std::isfinite(z[i]);
      r.valid += finite ? 1 : 0;
      if (truth.shadowed[i]) {
        r.shadow_valid += finite ? 1 : 0;
        continue;
      }
      if (!truth.lit[i]) continue;
      ++r.lit;
      if (!finite) continue;
      ++r.lit_valid;
      const double e = z[i] - truth.depth_m[i];
      sum += e * e;
      r.far_off += std::abs(e) > 0.04 ? 1 : 0;
    }
    r.rms_m = r.lit_valid > 0 ? std::sqrt(sum / static_cast<double>(r.lit_valid)) : 0.0;
    depth.push_back(r);
  }
};

AVS_REGISTER_COMPONENT(TestPlanePatterns);
AVS_REGISTER_COMPONENT(TestDepthRecorder);
AVS_REGISTER_COMPONENT(TestSimPlanePatterns);

/// Runs decode + source + recorder for `duration_s` of sim time in one lockstep container.
struct GraphRun {
  std::unique_ptr<graph::Graph> graph;
  std::unique_ptr<runtime::Container> container;
  TestPlanePatterns* source = nullptr;
  TestSimPlanePatterns* sim_source = nullptr;
  TestDepthRecorder* recorder = nullptr;
  runtime::Component* decode = nullptr;

  std::string diagnostic(const std::string& key) const {
    for (const auto& [k, v] : decode->diagnostic_values()) {
      if (k == key) return v;
    }
    return "<missing " + key + ">";
  }
  std::int64_t count(const std::string& key) const { return std::stoll(diagnostic(key)); }
};

GraphRun run_graph(double duration_s, const std::string& decode_params,
                   const std::string& source_params = "{}",
                   const std::string& source_type = "test_plane_patterns") {
  avs::testing::ContainerRun ran = avs::testing::run_lockstep_container(
      {"{type: " + source_type + ", name: source, parameters: " + source_params + "}",
       "{type: decode, name: decode, parameters: " + decode_params + "}",
       "{type: test_depth_recorder, name: recorder}"},
      duration_s);
  for (const auto& e : ran.load_errors) ADD_FAILURE() << e;
  GraphRun run;
  if (!ran.container) return run;
  EXPECT_EQ(ran.status, 0);
  run.source = ran.find<TestPlanePatterns>("source");
  run.sim_source = ran.find<TestSimPlanePatterns>("source");
  run.recorder = ran.find<TestDepthRecorder>("recorder");
  run.decode = ran.find<runtime::Component>("decode");
  run.graph = std::move(ran.graph);
  run.container = std::move(ran.container);
  EXPECT_TRUE(run.source != nullptr || run.sim_source != nullptr);
  EXPECT_NE(run.recorder, nullptr);
  EXPECT_NE(run.decode, nullptr);
  return run;
}

/// Section 4.3 with the default layout: code step dz = 19.2 mm at the image centre; a code
/// triangulated at its centre errs uniformly by +-dz/2, RMS dz / sqrt(12) = 5.5 mm.
constexpr double kCodeStepM = 0.0192;
const double kQuantisationRmsM = kCodeStepM / std::sqrt(12.0);

void expect_accurate(const DepthRecord& r, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_GE(r.lit_valid, r.lit * 99 / 100);
  EXPECT_EQ(r.shadow_valid, 0);
  EXPECT_LT(r.far_off * 200, r.valid);  // < 0.5 %
  EXPECT_LE(r.rms_m, 1.25 * kQuantisationRmsM);
}

TEST(DecodeComponent, RollingDepthPerPairMatchesThePlane) {
  const GraphRun run = run_graph(0.1, "{publish_points: true}");
  ASSERT_NE(run.recorder, nullptr);
  const auto& stamps = run.source->stamps_ns;
  const auto& depth = run.recorder->depth;
  ASSERT_GE(stamps.size(), 90u);
  // One depth image per pair: frame pairs (0,1), (2,3), ... -> stamp of the negative.
  const std::size_t pairs = stamps.size() / 2;
  ASSERT_EQ(depth.size(), pairs);
  for (std::size_t p = 0; p < pairs; ++p) {
    EXPECT_EQ(depth[p].stamp_ns, stamps[2 * p + 1]) << "pair " << p;
    if (p > 0) {
      EXPECT_EQ(depth[p].stamp_ns - depth[p - 1].stamp_ns, 2'000'000) << "500 Hz";
    }
    EXPECT_EQ(run.recorder->encodings[p], "32FC1");
    if (p < kBits - 1) {
      EXPECT_EQ(depth[p].valid, 0) << "pair " << p << ": not all bits measured yet";
    } else {
      expect_accurate(depth[p], "pair " + std::to_string(p));
    }
  }
  std::printf(
      "depth RMS %.2f mm (quantisation dz/sqrt(12) = %.2f mm), lit valid %.3f %%\n",
      1000 * depth.back().rms_m, 1000 * kQuantisationRmsM,
      100.0 * static_cast<double>(depth.back().lit_valid) / static_cast<double>(depth.back().lit));
  // /timing: one per depth image, same stamp.
  const auto& timing = run.recorder->timing;
  ASSERT_EQ(timing.size(), depth.size());
  for (std::size_t p = 0; p < pairs; ++p) {
    EXPECT_EQ(runtime::from_ros_time(timing[p]->header.stamp).ns, depth[p].stamp_ns);
    EXPECT_EQ(runtime::get_string(timing[p]->stage), "decode");
    EXPECT_GT(timing[p]->processing_ms, 0.0);
  }
  // /depth/info: the data age of every depth image once the window is full, same stamp, the
  // frame period measured from the stamps (1 ms), the age within the 2n-frame window.
  const auto& info = run.recorder->info;
  ASSERT_GE(info.size() + static_cast<std::size_t>(kBits), depth.size());
  ASSERT_LE(info.size(), depth.size());
  const std::size_t first = depth.size() - info.size();
  for (std::size_t i = 0; i < info.size(); ++i) {
    EXPECT_EQ(runtime::from_ros_time(info[i]->header.stamp).ns, depth[first + i].stamp_ns);
    EXPECT_NEAR(info[i]->frame_period_s, 1e-3, 1e-9);
    EXPECT_NEAR(info[i]->data_age_s,
                (2.0 * info[i]->effective_age_pairs + 0.5) * info[i]->frame_period_s, 1e-12);
    EXPECT_GT(info[i]->data_age_s, 0.0);
    EXPECT_LT(info[i]->data_age_s, 2 * kBits * 1e-3);
  }
  // Points: organised XYZ, z equal to the depth image.
  ASSERT_FALSE(run.recorder->points.empty());
  const auto& cloud = *run.recorder->points.back();
  const auto& last = *run.recorder->last_depth;
  EXPECT_EQ(cloud.width, last.width);
  EXPECT_EQ(cloud.height, last.height);
  EXPECT_EQ(cloud.point_step, 12u);
  ASSERT_EQ(cloud.data._length, 3 * last.data._length);
  const auto* xyz = reinterpret_cast<const float*>(cloud.data._buffer);
  const auto* z = reinterpret_cast<const float*>(last.data._buffer);
  const std::size_t centre = 256 * 512 + 300;
  EXPECT_EQ(xyz[3 * centre + 2], z[centre]);
  EXPECT_NEAR(xyz[3 * centre], z[centre] * (300 - 255.5) / 628.8, 1e-3);
  // Diagnostics.
  EXPECT_EQ(run.count("dropped_frames"), 0);
  EXPECT_EQ(run.count("out_of_order_frames"), 0);
  EXPECT_EQ(run.count("depth_published"), static_cast<std::int64_t>(pairs));
  EXPECT_EQ(run.count("frames_received"), static_cast<std::int64_t>(stamps.size()));
  EXPECT_GT(std::stod(run.diagnostic("processing_ms_mean")), 0.0);
  std::printf("decode component: processing_ms_mean %s, processing_ms_max %s (wall clock)\n",
              run.diagnostic("processing_ms_mean").c_str(),
              run.diagnostic("processing_ms_max").c_str());
}

TEST(DecodeComponent, DroppedFrameIsCountedAndInvalidatesOnlyItsBitsWindow) {
  // Frame 2 * 18 + 6 = the positive of bit 3 in cycle 2 is lost: pair (42, 43) cannot be
  // decoded; bit 3 is missing from the window until it is measured again in cycle 3.
  const std::int64_t lost = 2 * kFramesPerCycle + 2 * 3;
  const GraphRun run = run_graph(0.1, "{}", "{drop_frames: [" + std::to_string(lost) + "]}");
  ASSERT_NE(run.recorder, nullptr);
  EXPECT_EQ(run.count("dropped_frames"), 1);
  EXPECT_EQ(run.count("incomplete_pairs"), 1);
  EXPECT_EQ(run.count("out_of_order_frames"), 0);
  const auto& stamps = run.source->stamps_ns;
  const auto& depth = run.recorder->depth;
  const std::size_t pairs = stamps.size() / 2;
  ASSERT_EQ(depth.size(), pairs - 1);  // no depth for the broken pair
  const auto lost_pair = static_cast<std::size_t>(lost / 2);
  const std::size_t remeasured = lost_pair + kBits;
  for (const DepthRecord& r : depth) {
    const auto frame = static_cast<std::size_t>(
        std::find(stamps.begin(), stamps.end(), r.stamp_ns) - stamps.begin());
    ASSERT_LT(frame, stamps.size());
    ASSERT_EQ(frame % 2, 1u) << "depth stamped with a negative frame";
    const std::size_t pair = frame / 2;
    EXPECT_NE(pair, lost_pair);
    if (pair < kBits - 1 || (pair > lost_pair && pair < remeasured)) {
      EXPECT_EQ(r.valid, 0) << "pair " << pair << ": bit 3 is missing from its window";
    } else {
      expect_accurate(r, "pair " + std::to_string(pair));  // never a bit in the wrong place
    }
  }
}

TEST(DecodeComponent, OutOfOrderFrameIsDiscardedNotMisplaced) {
  // The positive of bit 5 in cycle 2 arrives after its negative: the negative has no positive
  // (incomplete), the late positive is older than the newest frame (out of order, discarded).
  const std::int64_t late = 2 * kFramesPerCycle + 2 * 5;
  const GraphRun run =
      run_graph(0.1, "{max_bit_age_pairs: 18}", "{swap_frames: [" + std::to_string(late) + "]}");
  ASSERT_NE(run.recorder, nullptr);
  EXPECT_EQ(run.count("out_of_order_frames"), 1);
  EXPECT_EQ(run.count("incomplete_pairs"), 1);
  EXPECT_EQ(run.count("dropped_frames"), 1);  // seen as a gap when the negative came first
  // With max_bit_age_pairs = 2n a static scene rides through: every map after the first
  // cycle is complete and right.
  const auto& depth = run.recorder->depth;
  ASSERT_GT(depth.size(), 40u);
  for (std::size_t i = kBits - 1; i < depth.size(); ++i) {
    expect_accurate(depth[i], "image " + std::to_string(i));
  }
  std::vector<double> ms;
  for (const auto& t : run.recorder->timing) ms.push_back(t->processing_ms);
  std::sort(ms.begin(), ms.end());
  std::printf(
      "decode component without points: /timing median %.3f ms, processing_ms_mean %s, "
      "max %s (wall clock)\n",
      ms[ms.size() / 2], run.diagnostic("processing_ms_mean").c_str(),
      run.diagnostic("processing_ms_max").c_str());
}

TEST(DecodeComponent, FullCycleModePublishesOncePerCycleLikeDecodeFullCycle) {
  const GraphRun run = run_graph(0.08, "{mode: full_cycle}");
  ASSERT_NE(run.recorder, nullptr);
  const auto& stamps = run.source->stamps_ns;
  const auto& depth = run.recorder->depth;
  ASSERT_EQ(depth.size(), stamps.size() / kFramesPerCycle);
  for (std::size_t c = 0; c < depth.size(); ++c) {
    EXPECT_EQ(depth[c].stamp_ns, stamps[c * kFramesPerCycle + kFramesPerCycle - 1]);
    expect_accurate(depth[c], "cycle " + std::to_string(c));
  }
  // Bit-identical to decode_full_cycle of the same frames.
  const SyntheticScene& scene = plane_scene();
  std::vector<PatternFrame> frames;
  for (int b = 0; b < kBits; ++b) {
    frames.push_back(scene.frame(b, Polarity::kPositive, 0));
    frames.push_back(scene.frame(b, Polarity::kNegative, 0));
  }
  DecoderConfig config;
  const FullCycleResult full = decode_full_cycle(config, frames);
  const auto* z = reinterpret_cast<const float*>(run.recorder->last_depth->data._buffer);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < full.depth_m.size(); ++i) {
    const bool same = std::isnan(z[i]) ? std::isnan(full.depth_m[i]) : z[i] == full.depth_m[i];
    differ += same ? 0 : 1;
  }
  EXPECT_EQ(differ, 0u);
}

TEST(DecodeComponent, SimulatorPlaneAtOneMetre) {
  // Frames from the simulator's renderer (its own pattern order, projector model, shading and
  // noise) against its ground truth.
  const GraphRun run = run_graph(0.06, "{}", "{}", "test_sim_plane_patterns");
  ASSERT_NE(run.sim_source, nullptr);
  const Truth& truth = run.sim_source->truth();
  double centre_depth = truth.depth_m[256 * 512 + 256];
  EXPECT_NEAR(centre_depth, 1.0, 1e-3);
  const auto& stamps = run.sim_source->stamps_ns;
  const auto& depth = run.recorder->depth;
  ASSERT_EQ(depth.size(), stamps.size() / 2);
  ASSERT_GT(depth.size(), static_cast<std::size_t>(kBits + 5));
  std::int64_t shadowed = 0;
  for (std::uint8_t v : truth.shadowed) shadowed += v;
  for (std::size_t p = kBits - 1; p < depth.size(); ++p) {
    EXPECT_EQ(depth[p].stamp_ns, stamps[2 * p + 1]);
    expect_accurate(depth[p], "pair " + std::to_string(p));
  }
  const DepthRecord& last = depth.back();
  std::printf(
      "simulator plane: depth RMS %.2f mm (dz/sqrt(12) = %.2f mm), lit valid %.3f %% of %lld, "
      "unlit surface valid %lld of %lld\n",
      1000 * last.rms_m, 1000 * kQuantisationRmsM,
      100.0 * static_cast<double>(last.lit_valid) / static_cast<double>(last.lit),
      static_cast<long long>(last.lit), static_cast<long long>(last.shadow_valid),
      static_cast<long long>(shadowed));
}

TEST(DecodeComponent, DropsAndTimingReachDiagnosticsOverDds) {
  // /diagnostics goes out once per second of the (sim) clock, to readers in other participants:
  // a plain DDS reader here sees the component's key/values (Component::diagnostic_values).
  const runtime::dds::Participant participant(avs::testing::test_domain());
  using Array = msgs::diagnostic_msgs::DiagnosticArray;
  const runtime::dds::Topic topic(participant, msg::TypeSupport<Array>::descriptor(),
                                  "rt/diagnostics", runtime::QosProfile{});
  const runtime::dds::Reader reader(participant, topic, runtime::QosProfile{});
  const GraphRun run = run_graph(1.05, "{}", "{drop_frames: [100, 501]}");
  ASSERT_NE(run.recorder, nullptr);
  std::map<std::string, std::string> values;
  avs::testing::take_diagnostic_statuses(reader, "test/decode", [&](const auto& status) {
    for (const auto& kv : runtime::as_span(status.values)) {
      values[std::string(runtime::get_string(kv.key))] = runtime::get_string(kv.value);
    }
  });
  ASSERT_FALSE(values.empty()) << "no /diagnostics status of test/decode received";
  EXPECT_EQ(values["dropped_frames"], "2");  // both drops happened before t = 1 s
  // Frame 100 is the positive of bit 5: its negative is an incomplete pair; frame 501 is the
  // negative of bit 7: its positive is simply replaced by the next one.
  EXPECT_EQ(values["incomplete_pairs"], "1");
  EXPECT_EQ(values["out_of_order_frames"], "0");
  EXPECT_GT(std::stod(values["processing_ms_mean"]), 0.0);
  EXPECT_TRUE(values.contains("callbacks")) << "the container's own values come first";
}

TEST(DecodeComponent, WrongFrameSizeIsRejectedAndCountedWithoutStoppingTheContainer) {
  // A calibration for a 256 x 256 camera does not match the 512 x 512 frames: every frame is
  // rejected with its reason and counted; the container runs to its end.
  const auto file = std::filesystem::temp_directory_path() /
                    ("avs_decode_cal_" + std::to_string(getpid()) + ".yaml");
  {
    std::ofstream out(file);
    out << "camera: {width: 256, height: 256, fx: 314.4, fy: 314.4, cx: 127.5, cy: 127.5}\n";
  }
  ::testing::internal::CaptureStderr();
  const GraphRun run = run_graph(0.02, "{calibration_file: " + file.string() + "}");
  const std::string err = ::testing::internal::GetCapturedStderr();
  std::filesystem::remove(file);
  ASSERT_NE(run.recorder, nullptr);
  EXPECT_NE(err.find("size 512x512, the calibration's camera is 256x256"), std::string::npos)
      << err;
  EXPECT_EQ(run.recorder->depth.size(), 0u);
  EXPECT_EQ(run.count("rejected_samples"), static_cast<std::int64_t>(run.source->stamps_ns.size()));
  EXPECT_EQ(run.count("frames_received"), 0);
}

/// Sends `count` malformed /camera/pattern frames from this (child) process once decode's
/// reader is matched: bit index 200, bit count 0 and 16, rgb8, 0x0, short data, in turn.
int publish_malformed_frames(int domain, int count) {
  const runtime::dds::Participant participant(domain);
  using Frame = msgs::avs_msgs::PatternFrame;
  runtime::QosProfile qos;
  qos.depth = 4;
  const runtime::dds::Topic topic(participant, msg::TypeSupport<Frame>::descriptor(),
                                  "rt/camera/pattern", qos);
  runtime::dds::Writer writer(participant, topic, qos);
  for (int wait = 0; writer.matched_readers() == 0; ++wait) {
    if (wait > 2000) return 3;  // 20 s without decode's reader
    usleep(10000);
  }
  for (int i = 0; i < count; ++i) {
    auto m = runtime::make_sample<Frame>();
    m->bit_count = kBits;
    m->bit_index = 1;
    auto& image = m->image;
    runtime::set_string(image.encoding, "mono8");
    image.width = image.height = image.step = 512;
    std::uint32_t bytes = 512 * 512;
    switch (i % 6) {
      case 0:
        m->bit_index = 200;
        break;
      case 1:
        m->bit_count = 0;
        break;
      case 2:
        m->bit_count = 16;
        break;
      case 3:
        runtime::set_string(image.encoding, "rgb8");
        break;
      case 4:
        image.width = image.height = image.step = 0;
        bytes = 0;
        break;
      default:
        bytes = 1000;
        break;  // short data
    }
    runtime::resize_sequence(image.data, bytes);
    writer.write(m.get());
    usleep(5000);
  }
  usleep(200000);  // let reliable delivery finish before the participant goes
  return 0;
}

TEST(DecodeComponent, MalformedFramesFromAnotherProcessAreRejectedAndDepthGoesOn) {
  // Issue 13 section 3: a second process publishes malformed frames into a running decode
  // graph; the container keeps producing depth from the good frames and the counter rises.
  const int kDomain = avs::testing::test_domain();
  constexpr int kBad = 30;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) _exit(publish_malformed_frames(kDomain, kBad));
  // Long enough in sim time (lockstep: several seconds of wall time) for the child to be
  // discovered and send everything while the graph runs.
  const GraphRun run = run_graph(4.0, "{}");
  int child_status = 0;
  ASSERT_EQ(waitpid(child, &child_status, 0), child);
  ASSERT_TRUE(WIFEXITED(child_status));
  ASSERT_EQ(WEXITSTATUS(child_status), 0) << "the publisher never matched decode's reader";
  ASSERT_NE(run.recorder, nullptr);
  const std::int64_t rejected = run.count("rejected_samples");
  EXPECT_GE(rejected, 1) << "no malformed frame reached decode";
  EXPECT_LE(rejected, kBad);
  // Every good pair still gave its depth map, none disturbed by the bad frames.
  const std::size_t pairs = run.source->stamps_ns.size() / 2;
  EXPECT_EQ(run.recorder->depth.size(), pairs);
  EXPECT_EQ(run.count("dropped_frames"), 0);
  EXPECT_EQ(run.count("out_of_order_frames"), 0);
  for (std::size_t p = kBits - 1; p < run.recorder->depth.size(); ++p) {
    expect_accurate(run.recorder->depth[p], "pair " + std::to_string(p) + " beside the bad frames");
  }
}

#ifdef AVS_PROGRAM
/// Issue 18 section 1: a running decode graph, `avs param set decode threshold_psi 30` from
/// another process; the next depth maps use it (fewer valid pixels in the low-contrast scene),
/// /parameter_events carries it, and refused changes say why.
TEST(DecodeComponent, ThresholdSetFromAnotherProcessAppliesToTheNextDepthMaps) {
  namespace rcl = msgs::rcl_interfaces;
  runtime::dds::Participant participant(avs::testing::test_domain());
  runtime::dds::Topic events_topic(participant, msg::TypeSupport<rcl::ParameterEvent>::descriptor(),
                                   runtime::kParameterEventsTopic, runtime::parameter_events_qos());
  runtime::dds::Reader events(participant, events_topic, runtime::parameter_events_qos());

  avs::testing::BackgroundContainer graph(
      {"{type: test_plane_patterns, name: source, parameters: {low_contrast: true}}",
       "{type: decode, name: decode}", "{type: test_depth_recorder, name: recorder}"},
      3600.0);
  for (const auto& e : graph.run().load_errors) ADD_FAILURE() << e;
  ASSERT_NE(graph.run().container, nullptr);
  const auto dir =
      std::filesystem::temp_directory_path() / ("avs_param_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto out = dir / "out.txt";
  const auto err = dir / "err.txt";
  const auto avs = [&](std::vector<std::string> words) {
    return avs::testing::run_avs(std::move(words), out, err);
  };

  // 1. The change, from another process, once the graph has run a while at psi 10.
  while (graph.run().container->now().ns < 200'000'000) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(avs({"param", "set", "decode", "threshold_psi", "30"}), 0)
      << avs::testing::read_file(err);
  EXPECT_NE(avs::testing::read_file(out).find("/decode: threshold_psi = 30 (was 10)"),
            std::string::npos)
      << avs::testing::read_file(out);

  // 2. /parameter_events carries it, stamped with the container's (sim) time of the change.
  std::int64_t changed_at_ns = -1;
  for (int attempt = 0; attempt < 500 && changed_at_ns < 0; ++attempt) {
    auto event = runtime::make_sample<rcl::ParameterEvent>();
    void* buffers[1] = {event.get()};
    dds_sample_info_t info;
    if (dds_take(events.get(), buffers, &info, 1, 1) > 0 && info.valid_data) {
      EXPECT_EQ(runtime::get_string(event->node), "/decode");
      ASSERT_EQ(event->changed_parameters._length, 1u);
      EXPECT_EQ(runtime::get_string(event->changed_parameters._buffer[0].name), "threshold_psi");
      EXPECT_EQ(event->changed_parameters._buffer[0].value.type, 2);  // PARAMETER_INTEGER
      EXPECT_EQ(event->changed_parameters._buffer[0].value.integer_value, 30);
      changed_at_ns = runtime::from_ros_time(event->stamp).ns;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  ASSERT_GT(changed_at_ns, 0) << "no /parameter_events sample";

  // 3. Refusals say why; reads show the value in force.
  EXPECT_EQ(avs({"param", "set", "decode", "threshold_psi", "300"}), 1);
  EXPECT_NE(avs::testing::read_file(err).find("expected an integer in [0, 255], got 300"),
            std::string::npos)
      << avs::testing::read_file(err);
  EXPECT_EQ(avs({"param", "set", "decode", "bit_count", "8"}), 1);
  EXPECT_NE(avs::testing::read_file(err).find("bit_count is not dynamic"), std::string::npos)
      << avs::testing::read_file(err);
  EXPECT_EQ(avs({"param", "set", "decode", "no_such_threshold", "1"}), 1);
  EXPECT_NE(avs::testing::read_file(err).find("unknown parameter 'no_such_threshold'"),
            std::string::npos)
      << avs::testing::read_file(err);
  EXPECT_EQ(avs({"param", "get", "decode", "threshold_psi"}), 0) << avs::testing::read_file(err);
  EXPECT_EQ(avs::testing::read_file(out), "30\n");
  EXPECT_EQ(avs({"param", "list", "decode"}), 0) << avs::testing::read_file(err);
  const std::string list = avs::testing::read_file(out);
  EXPECT_TRUE(std::regex_search(list, std::regex("\n  threshold_psi +integer, dynamic\n"))) << list;
  EXPECT_TRUE(std::regex_search(list, std::regex("\n  bit_count +integer, restart\n"))) << list;
  EXPECT_EQ(avs({"param", "dump", "decode"}), 0) << avs::testing::read_file(err);
  const std::string dump = avs::testing::read_file(out);

  // 4. Enough depth maps after the change: a whole cycle (every bit binarised with psi 30).
  constexpr std::int64_t kCycleNs = 2'000'000LL * kBits;
  while (graph.run().container->now().ns < changed_at_ns + 10 * kCycleNs) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(graph.stop(), 0);
  const auto* recorder = graph.run().find<TestDepthRecorder>("recorder");
  ASSERT_NE(recorder, nullptr);
  double before = 0, after = 0;
  int before_n = 0, after_n = 0;
  for (const DepthRecord& r : recorder->depth) {
    if (r.stamp_ns >= changed_at_ns - 10 * kCycleNs && r.stamp_ns < changed_at_ns - 2'000'000) {
      before += static_cast<double>(r.valid);
      ++before_n;
    } else if (r.stamp_ns > changed_at_ns + kCycleNs) {
      after += static_cast<double>(r.valid);
      ++after_n;
    }
  }
  ASSERT_GT(before_n, 0);
  ASSERT_GT(after_n, 0);
  before /= before_n;
  after /= after_n;
  std::printf("valid pixels per depth map: %.0f at psi 10 (%d maps), %.0f at psi 30 (%d maps)\n",
              before, before_n, after, after_n);
  EXPECT_LT(after, 0.8 * before);

  // 5. The dump is a `parameters:` block the graph loader takes, with the value in force.
  const auto file = dir / "dumped.yaml";
  {
    std::ofstream yaml(file);
    yaml << "containers:\n  - name: c\n    components:\n      - type: decode\n        name: d\n"
         << "        parameters:\n";
    std::istringstream lines(dump);
    for (std::string line; std::getline(lines, line);) yaml << "          " << line << "\n";
  }
  const graph::LoadResult loaded = graph::load_graph(file.string(), {});
  for (const auto& e : loaded.errors) ADD_FAILURE() << e.str() << "\n" << dump;
  ASSERT_TRUE(loaded.ok());
  EXPECT_EQ(loaded.graph->containers.front().components.front().parameters.get<std::int64_t>(
                "threshold_psi"),
            30);
  std::filesystem::remove_all(dir);
}
#endif  // AVS_PROGRAM

}  // namespace
}  // namespace avs::decode
