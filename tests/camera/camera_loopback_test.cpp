// The capture path over the real GigE Vision protocol on loopback (issue 15 section 3):
// sim_camera (the simulator behind Aravis's GV fake camera, GVCP/GVSP on 127.0.0.1) ->
// camera (Aravis, PatternSequencer) -> decode, in one wall-clock container. A recorder takes
// every /camera/pattern frame: its bytes must be the simulator's frame k (k from the stamp,
// the sim camera's clock k / rate), its label frame k's true pattern; it feeds the same frames
// with the same labels to a RollingDecoder of its own (the direct simulator path), and every
// /depth/image decode publishes must equal that decoder's map bit for bit. With frames dropped
// on purpose, every gap is counted and depth resumes after it.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "aravis_camera.hpp"
#include "avs/decode/rolling_decoder.hpp"
#include "avs/runtime/component.hpp"
#include "avs/sim/scene.hpp"
#include "avs/sim/simulator.hpp"
#include "avs/testing/lockstep_graph.hpp"
#include "sim_gige_camera.hpp"

namespace avs::camera {
namespace {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

constexpr double kRateHz = 200;  // the sim camera's pattern rate (5 ms: loopback keeps up)
constexpr int kBits = 9;
constexpr int kPrerenderCycles = 2;

/// Checks /camera/pattern against the simulator and decodes it directly; compares /depth/image.
class TestCameraChecker final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_100;
    keep_last_100.depth = 100;
    return {.type = "test_camera_checker",
            .description = "tests: /camera/pattern vs the simulator, /depth/image vs direct decode",
            .parameters = {},
            .publishes = {},
            .subscribes = {
                runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                            keep_last_100),
                runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image", keep_last_100)}};
  }

  explicit TestCameraChecker(ComponentContext& ctx)
      : Component(ctx),
        sim_(sim_config(), sim::Scene{{sim::make_background_plane(1.04)}}),
        decoder_(decode::DecoderConfig{}) {
    // The frames sim_camera repeats (prerender_cycles), rendered the same way.
    for (std::uint64_t k = 0; k < kPrerenderCycles * 2 * kBits; ++k) {
      frames_.push_back(
          sim_.render(k, static_cast<double>(k) / kRateHz, sim::HeadState{}).image.pixels);
    }
    ctx.subscribe<msgs::avs_msgs::PatternFrame>(
        "pattern", [this](runtime::SamplePtr<msgs::avs_msgs::PatternFrame> m) { on_pattern(*m); });
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth(*m); });
  }

  std::int64_t patterns = 0, wrong_bytes = 0, wrong_labels = 0;
  std::int64_t depth_maps = 0, equal_maps = 0, unmatched_maps = 0, valid_pixels = 0;
  std::vector<std::int64_t> pattern_k;  ///< frame number of every labelled frame
  std::vector<std::int64_t> depth_k;    ///< of the newest frame of every depth map

 private:
  static sim::SimulatorConfig sim_config() {
    sim::SimulatorConfig c;
    c.frame_rate_hz = kRateHz;
    return c;
  }

  static std::int64_t frame_number(const msgs::builtin_interfaces::Time& stamp) {
    const std::int64_t ns = runtime::from_ros_time(stamp).ns;
    return std::llround(static_cast<double>(ns) * 1e-9 * kRateHz) - 1;  // stamp (k + 1) / rate
  }

  void on_pattern(const msgs::avs_msgs::PatternFrame& m) {
    const std::int64_t k = frame_number(m.header.stamp);
    ++patterns;
    pattern_k.push_back(k);
    const auto& truth = frames_[static_cast<std::size_t>(k) % frames_.size()];
    if (m.image.data._length != truth.size() ||
        std::memcmp(m.image.data._buffer, truth.data(), truth.size()) != 0) {
      ++wrong_bytes;
    }
    const sim::PatternSlot slot = sim::pattern_slot(static_cast<std::uint64_t>(k), kBits);
    if (m.bit_index != slot.bit_index || m.positive != slot.positive) ++wrong_labels;
    decode::PatternFrame frame;
    frame.image = {m.image.data._buffer, static_cast<int>(m.image.width),
                   static_cast<int>(m.image.height), static_cast<std::ptrdiff_t>(m.image.step)};
    frame.bit_index = m.bit_index;
    frame.polarity = m.positive ? decode::Polarity::kPositive : decode::Polarity::kNegative;
    frame.cycle = m.cycle;
    const decode::DecodeResult r = decoder_.push_frame(frame);
    if (r.depth_updated) {
      direct_[k].assign(r.depth_m.begin(), r.depth_m.end());
      while (direct_.size() > 200)  // the lane may run far ahead of the depth maps
        direct_.erase(direct_.begin());
    }
  }

  void on_depth(const msgs::sensor_msgs::Image& m) {
    const std::int64_t k = frame_number(m.header.stamp);
    ++depth_maps;
    depth_k.push_back(k);
    const auto it = direct_.find(k);
    if (it == direct_.end()) {
      ++unmatched_maps;
      return;
    }
    const auto* z = reinterpret_cast<const float*>(m.data._buffer);
    const std::vector<float>& direct = it->second;
    bool equal = m.data._length == 4 * direct.size();
    for (std::size_t i = 0; equal && i < direct.size(); ++i) {
      equal = (std::isnan(z[i]) && std::isnan(direct[i])) || z[i] == direct[i];
      valid_pixels += std::isfinite(z[i]) ? 1 : 0;
    }
    equal_maps += equal ? 1 : 0;
  }

  sim::Simulator sim_;
  decode::RollingDecoder decoder_;
  std::vector<std::vector<std::uint8_t>> frames_;
  std::map<std::int64_t, std::vector<float>> direct_;  ///< by frame number of the negative
};

AVS_REGISTER_COMPONENT(TestCameraChecker);

std::map<std::string, std::string> diagnostics(const testing::ContainerRun& run,
                                               const std::string& name) {
  std::map<std::string, std::string> out;
  if (runtime::Component* c = run.container ? run.container->find_component(name) : nullptr) {
    for (auto& [key, value] : c->diagnostic_values()) out[key] = value;
  }
  return out;
}

std::int64_t count(const std::map<std::string, std::string>& d, const std::string& key) {
  const auto it = d.find(key);
  return it == d.end() ? -1 : std::stoll(it->second);
}

/// sim_camera + camera + decode + checker on the wall clock for `seconds`.
testing::ContainerRun run_loopback(const std::string& sim_camera_extra, double seconds) {
  const std::string rate = std::to_string(kRateHz);
  return testing::run_wall_clock_container(
      // The checker and decode first: active before the camera's first frame. Decode keeps the
      // newest 100 frames instead of its 4 (docs/runtime.md, skip to the newest): this test
      // compares every map bit for bit, so on a loaded machine decode must catch up rather
      // than skip frames the checker's own decoder got.
      {"{type: test_camera_checker, name: checker}",
       "{type: decode, name: decode, qos: {pattern: {depth: 100}}}",
       "{type: sim_camera, name: sim_camera, parameters: {frame_rate_hz: " + rate +
           ", prerender_cycles: " + std::to_string(kPrerenderCycles) + ", first_frame_id: 65200" +
           sim_camera_extra + "}}",
       "{type: camera, name: camera, parameters: {device_id: 127.0.0.1, trigger_mode: free_run, "
       "frame_rate_hz: " +
           rate + ", stamp_source: camera, socket_buffer_bytes: 8000000, image_raw_rate_hz: 10}}"},
      seconds);
}

TEST(CameraLoopback, DepthOverGigEVisionEqualsTheDirectSimulatorPath) {
  const testing::ContainerRun run = run_loopback("", 6.0);
  ASSERT_TRUE(run.load_errors.empty()) << run.load_errors.front();
  ASSERT_EQ(run.status, 0);
  const auto* checker = run.find<TestCameraChecker>("checker");
  ASSERT_NE(checker, nullptr);
  const auto camera = diagnostics(run, "camera");
  EXPECT_GT(checker->patterns, 200) << "frames labelled in 6 s at " << kRateHz << " Hz";
  EXPECT_EQ(checker->wrong_bytes, 0);
  EXPECT_EQ(checker->wrong_labels, 0);
  EXPECT_GT(checker->depth_maps, 100);
  EXPECT_EQ(checker->unmatched_maps, 0);
  EXPECT_EQ(checker->equal_maps, checker->depth_maps);
  EXPECT_GT(checker->valid_pixels, 0);
  EXPECT_GE(count(camera, "locks"), 1);
  // Frame ids went 65200 .. 65535, 1, ...: the wrap is no restart.
  EXPECT_GT(count(camera, "frames_received"), 340);
  EXPECT_EQ(count(camera, "restarts"), 0);
}

TEST(CameraLoopback, FramesDroppedOnPurposeAreCountedAndDepthResumes) {
  // Single drops, a pair, a burst of 30 (beyond a cycle, bridged by ids and timestamps).
  const std::vector<int> drops = {120, 200, 201, 300, 301, 302, 303, 304, 305, 306, 307, 308,
                                  309, 310, 311, 312, 313, 314, 315, 316, 317, 318, 319, 320,
                                  321, 322, 323, 324, 325, 326, 327, 328, 329, 450};
  std::string list;
  for (int k : drops) list += (list.empty() ? "" : ", ") + std::to_string(k);
  const testing::ContainerRun run = run_loopback(", drop_frames: [" + list + "]", 6.0);
  ASSERT_TRUE(run.load_errors.empty()) << run.load_errors.front();
  ASSERT_EQ(run.status, 0);
  const auto* checker = run.find<TestCameraChecker>("checker");
  ASSERT_NE(checker, nullptr);
  const auto camera = diagnostics(run, "camera");
  EXPECT_EQ(checker->wrong_bytes, 0);
  EXPECT_EQ(checker->wrong_labels, 0);
  EXPECT_EQ(checker->unmatched_maps, 0);
  EXPECT_EQ(checker->equal_maps, checker->depth_maps);
  // Every dropped frame is a missing id (the loaded machine may lose more: never fewer).
  EXPECT_GE(count(camera, "missing_frame_ids"), static_cast<std::int64_t>(drops.size()));
  EXPECT_GE(count(camera, "gaps"), 4);
  for (int k : drops) {
    EXPECT_EQ(std::count(checker->pattern_k.begin(), checker->pattern_k.end(), k), 0) << k;
  }
  // Depth after the last gap.
  EXPECT_TRUE(std::any_of(checker->depth_k.begin(), checker->depth_k.end(),
                          [](std::int64_t k) { return k > 450 + 2 * 2 * kBits; }));
}

/// What AravisCamera says when the camera refuses a configuration: one line naming the
/// feature, the value and what the camera allows.
std::string configure_error(const CameraConfig& config) {
  SimGigECamera served(SimGigECameraConfig{}, 512, 512, [](std::uint64_t, std::uint8_t* out) {
    std::fill(out, out + 512 * 512, std::uint8_t{0});
  });
  try {
    AravisCamera camera(config);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

CameraConfig loopback_config() {
  CameraConfig c;
  c.device_id = "127.0.0.1";
  c.trigger_mode = TriggerMode::kFreeRun;
  c.frame_rate_hz = 200;
  return c;
}

TEST(CameraLoopback, RejectedFeaturesAreOneLineNamingFeatureValueAndWhatIsAllowed) {
  CameraConfig wide = loopback_config();
  wide.width = 4000;
  EXPECT_EQ(configure_error(wide),
            "camera 127.0.0.1: Width = 4000 is out of range; the camera allows 1..2048");
  CameraConfig source = loopback_config();
  source.trigger_mode = TriggerMode::kHardware;
  source.trigger_source = "Line7";
  const std::string error = configure_error(source);
  EXPECT_NE(error.find("camera 127.0.0.1: TriggerSource = Line7 rejected"), std::string::npos)
      << error;
  EXPECT_NE(error.find("the camera allows Line0, Software"), std::string::npos) << error;
  CameraConfig fast = loopback_config();
  fast.frame_rate_hz = 5000;
  EXPECT_EQ(configure_error(fast),
            "camera 127.0.0.1: AcquisitionFrameRate = 5000 is out of range; the camera allows "
            "0.1..1000");
  CameraConfig mono16 = loopback_config();
  mono16.pixel_format = "Mono16";
  EXPECT_EQ(configure_error(mono16),
            "camera 127.0.0.1: PixelFormat = Mono16 is not supported by avs (decode takes "
            "Mono8); the camera allows Mono8");
  EXPECT_EQ(configure_error(loopback_config()), "(no error)");
}

TEST(CameraLoopback, UnknownDeviceListsTheCamerasFound) {
  CameraConfig missing = loopback_config();
  missing.device_id = "Nobody-NoCam-0000";
  const std::string error = configure_error(missing);
  EXPECT_NE(error.find("camera: cannot open 'Nobody-NoCam-0000'"), std::string::npos) << error;
  EXPECT_NE(error.find("cameras found: "), std::string::npos) << error;
}

TEST(CameraLoopback, NoCameraAtAllIsOneClearLine) {
  // No sim camera serving (this test holds the GVCP port lock): discovery finds nothing.
  CameraConfig any = loopback_config();
  any.device_id.clear();
  std::string error = "(no error)";
  try {
    AravisCamera camera(any);
  } catch (const std::exception& e) {
    error = e.what();
  }
  EXPECT_EQ(error.rfind("camera: no GenICam camera found", 0), 0u) << error;
}

}  // namespace
}  // namespace avs::camera
