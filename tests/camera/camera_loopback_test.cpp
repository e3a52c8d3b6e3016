// The capture path over the real GigE Vision protocol on loopback (issue 15 section 3):
// sim_camera (the simulator behind Aravis's GV fake camera, GVCP/GVSP on 127.0.0.1) ->
// camera (Aravis, PatternSequencer) -> decode, in one wall-clock container. A recorder takes
// every /camera/pattern frame: its bytes must be the simulator's frame k (k from the stamp,
// the sim camera's clock k / rate), its label frame k's true pattern; it feeds the same frames
// with the same labels to a RollingDecoder of its own (the direct simulator path), and every
// /depth/image decode publishes must equal that decoder's map bit for bit. With frames dropped
// on purpose, every gap is counted and depth resumes after it. With the ken in the scene, two
// `matching` instances take the maps of both paths: the poses must agree within 1e-6.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "aravis_camera.hpp"
#include "avs/decode/rolling_decoder.hpp"
#include "avs/runtime/component.hpp"
#include "avs/sim/scene.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/simulator.hpp"
#include "avs/testing/lockstep_graph.hpp"
#ifdef AVS_PROGRAM
#include "avs_program.hpp"
#endif
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
            .parameters = {ParamSpec::string("scene", "", "scene YAML (empty: a plane at 1.04 m)"),
                           ParamSpec::boolean("forward_maps", false,
                                              "forward both paths' maps to two matchings")},
            .publishes = {runtime::port<msgs::sensor_msgs::Image>(
                              "checked_depth", "/checked/depth/image", keep_last_100),
                          runtime::port<msgs::sensor_msgs::Image>(
                              "direct_depth", "/direct/depth/image", keep_last_100)},
            .subscribes = {
                runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                            keep_last_100),
                runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image", keep_last_100),
                runtime::port<msgs::geometry_msgs::PoseStamped>(
                    "checked_pose", "/checked/object/pose", keep_last_100),
                runtime::port<msgs::geometry_msgs::PoseStamped>(
                    "direct_pose", "/direct/object/pose", keep_last_100)}};
  }

  explicit TestCameraChecker(ComponentContext& ctx)
      : Component(ctx),
        sim_(make_simulator(ctx.param<std::string>("scene"))),
        decoder_(decode::DecoderConfig{}),
        forward_maps_(ctx.param<bool>("forward_maps")),
        checked_depth_(ctx.publisher<msgs::sensor_msgs::Image>("checked_depth")),
        direct_depth_(ctx.publisher<msgs::sensor_msgs::Image>("direct_depth")) {
    // The frames sim_camera repeats (prerender_cycles), rendered the same way.
    for (std::uint64_t k = 0; k < kPrerenderCycles * 2 * kBits; ++k) {
      frames_.push_back(
          sim_.render(k, static_cast<double>(k) / kRateHz, sim::HeadState{}).image.pixels);
    }
    ctx.subscribe<msgs::avs_msgs::PatternFrame>(
        "pattern", [this](runtime::SamplePtr<msgs::avs_msgs::PatternFrame> m) { on_pattern(*m); });
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth(*m); });
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "checked_pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) {
          checked_poses[frame_number(m->header.stamp)] = pose_of(*m);
        });
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "direct_pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) {
          direct_poses[frame_number(m->header.stamp)] = pose_of(*m);
        });
  }

  /// Position (m) and orientation (x, y, z, w) of each pose, by frame number of its map.
  std::map<std::int64_t, std::array<double, 7>> checked_poses, direct_poses;
  std::int64_t forwarded_maps = 0;

  std::int64_t patterns = 0, wrong_bytes = 0, wrong_labels = 0;
  std::int64_t depth_maps = 0, equal_maps = 0, unmatched_maps = 0, valid_pixels = 0;
  std::vector<std::int64_t> pattern_k;  ///< frame number of every labelled frame
  std::vector<std::int64_t> depth_k;    ///< of the newest frame of every depth map

 private:
  /// The simulator sim_camera serves (its make_simulator: the scene file's, at our rate).
  static sim::Simulator make_simulator(const std::string& scene) {
    sim::SimulatorConfig c;
    sim::Scene objects{{sim::make_background_plane(1.04)}};
    if (!scene.empty()) {
      sim::SceneFile file = sim::load_scene(scene);
      c = file.config;
      objects = std::move(file.scene);
    }
    c.frame_rate_hz = kRateHz;
    return sim::Simulator(c, std::move(objects));
  }

  static std::array<double, 7> pose_of(const msgs::geometry_msgs::PoseStamped& m) {
    const auto& p = m.pose.position;
    const auto& q = m.pose.orientation;
    return {p.x, p.y, p.z, q.x, q.y, q.z, q.w};
  }

  /// A 32FC1 map as decode publishes it.
  static std::shared_ptr<msgs::sensor_msgs::Image> depth_image(const msgs::sensor_msgs::Image& like,
                                                               const float* z, std::size_t count) {
    auto image = runtime::make_sample<msgs::sensor_msgs::Image>();
    image->header.stamp = like.header.stamp;
    runtime::set_string(image->header.frame_id,
                        like.header.frame_id != nullptr ? like.header.frame_id : "");
    runtime::set_string(image->encoding, "32FC1");
    image->width = like.width;
    image->height = like.height;
    image->step = like.step;
    runtime::resize_sequence(image->data, static_cast<std::uint32_t>(4 * count));
    std::memcpy(image->data._buffer, z, 4 * count);
    return image;
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
    // Both paths' maps to the two matchings, from the third map on (decode's /depth/camera_info
    // has long reached both by then), so that each starts from the same map and sees the
    // same ones: the capture path's (the bytes decode published) and the direct path's.
    if (forward_maps_ && depth_maps > 2) {
      ++forwarded_maps;
      checked_depth_.publish(depth_image(m, z, direct.size()));
      direct_depth_.publish(depth_image(m, direct.data(), direct.size()));
    }
  }

  sim::Simulator sim_;
  decode::RollingDecoder decoder_;
  bool forward_maps_;
  runtime::Publisher<msgs::sensor_msgs::Image> checked_depth_, direct_depth_;
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
testing::ContainerRun run_loopback(const std::string& sim_camera_extra, double seconds,
                                   const std::string& checker_parameters = "{}",
                                   const std::vector<std::string>& more = {}) {
  const std::string rate = std::to_string(kRateHz);
  std::vector<std::string> components =
      // The checker and decode first: active before the camera's first frame. Decode keeps the
      // newest 100 frames instead of its 4 (docs/runtime.md, skip to the newest): this test
      // compares every map bit for bit, so on a loaded machine decode must catch up rather
      // than skip frames the checker's own decoder got.
      {"{type: test_camera_checker, name: checker, parameters: " + checker_parameters + "}",
       "{type: decode, name: decode, qos: {pattern: {depth: 100}}}",
       "{type: sim_camera, name: sim_camera, parameters: {frame_rate_hz: " + rate +
           ", prerender_cycles: " + std::to_string(kPrerenderCycles) + ", first_frame_id: 65200" +
           sim_camera_extra + "}}",
       "{type: camera, name: camera, parameters: {device_id: 127.0.0.1, trigger_mode: free_run, "
       "frame_rate_hz: " +
           rate + ", stamp_source: camera, socket_buffer_bytes: 8000000, image_raw_rate_hz: 10}}"};
  components.insert(components.end(), more.begin(), more.end());
  return testing::run_wall_clock_container(components, seconds);
}

/// A `matching` on the maps of one path (`checked` or `direct`), with its own topics; it keeps
/// every map (no skipping to the newest), so both see the same ones.
std::string matching_on(const std::string& path) {
  return "{type: matching, name: matching_" + path + ", remap: {depth: /" + path +
         "/depth/image, pose: /" + path + "/object/pose, pose_world: /" + path +
         "/object/pose_world, match: /" + path + "/object/match, timing: /" + path +
         "/timing}, qos: {depth: {depth: 1000}}}";
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

TEST(CameraLoopback, PosesOverGigEVisionEqualTheDirectSimulatorPath) {
  // The ken 1 m ahead (static_ken.yaml): matching on the maps that came over GigE Vision and
  // matching on the direct simulator path's maps give the same poses (issue 15: within 1e-6).
  const std::string scene =
      std::string(std::getenv("AVS_SOURCE_DIR")) + "/launch_config/scenes/static_ken.yaml";
  const testing::ContainerRun run =
      run_loopback(", scene: " + scene, 6.0, "{scene: " + scene + ", forward_maps: true}",
                   {matching_on("checked"), matching_on("direct")});
  ASSERT_TRUE(run.load_errors.empty()) << run.load_errors.front();
  ASSERT_EQ(run.status, 0);
  const auto* checker = run.find<TestCameraChecker>("checker");
  ASSERT_NE(checker, nullptr);
  EXPECT_EQ(checker->wrong_bytes, 0);
  EXPECT_EQ(checker->wrong_labels, 0);
  EXPECT_EQ(checker->unmatched_maps, 0);
  EXPECT_EQ(checker->equal_maps, checker->depth_maps);
  // Counts only need to show that both paths were matched: how many maps and poses come in 6 s
  // depends on the machine (about 500 here, 25 under ASan in CI).
  EXPECT_GT(checker->forwarded_maps, 10);
  // Poses of the same maps (the run may stop between the two matchings' turns at the end).
  std::int64_t common = 0;
  double position_m = 0, orientation = 0;
  for (const auto& [k, a] : checker->checked_poses) {
    const auto it = checker->direct_poses.find(k);
    if (it == checker->direct_poses.end()) continue;
    ++common;
    const auto& b = it->second;
    position_m =
        std::max({position_m, std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
    // Quaternion components (q and -q are the same rotation).
    double same = 0, opposite = 0;
    for (int i = 3; i < 7; ++i) {
      same = std::max(same, std::abs(a[i] - b[i]));
      opposite = std::max(opposite, std::abs(a[i] + b[i]));
    }
    orientation = std::max(orientation, std::min(same, opposite));
  }
  std::printf(
      "%lld maps forwarded, %zu / %zu poses (capture path / direct path), %lld common: "
      "largest difference %.3g m, %.3g in a quaternion component\n",
      static_cast<long long>(checker->forwarded_maps), checker->checked_poses.size(),
      checker->direct_poses.size(), static_cast<long long>(common), position_m, orientation);
  EXPECT_GE(common, 5);
  EXPECT_GE(static_cast<std::int64_t>(checker->direct_poses.size()), common);
  EXPECT_LE(position_m, 1e-6);
  EXPECT_LE(orientation, 1e-6);  // about 2e-6 rad
  // And the pose is the ken where the scene puts it: 1 m ahead on the optical axis.
  ASSERT_FALSE(checker->checked_poses.empty());
  const auto& last = checker->checked_poses.rbegin()->second;
  EXPECT_NEAR(last[2], 1.0, 0.05);
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

#ifdef AVS_PROGRAM
/// Issue 18 section 1: the camera's exposure, gain and sequencer threshold changed from another
/// process while it streams (`avs param set camera ...`): written to the camera over GVCP and
/// read back (AravisCamera checks that it stuck), the labelled frames go on, and a value the
/// camera does not allow is refused with its range and changes nothing.
TEST(CameraLoopback, ExposureGainAndThresholdChangeWhileStreaming) {
  const std::string rate = std::to_string(kRateHz);
  avs::testing::BackgroundContainer graph(
      {"{type: sim_camera, name: sim_camera, parameters: {frame_rate_hz: " + rate + "}}",
       "{type: camera, name: camera, parameters: {device_id: 127.0.0.1, trigger_mode: free_run, "
       "frame_rate_hz: " +
           rate + ", socket_buffer_bytes: 8000000}}"},
      3600.0, avs::testing::TestClock::wall);
  for (const auto& e : graph.run().load_errors) ADD_FAILURE() << e;
  ASSERT_NE(graph.run().container, nullptr);
  const auto labelled = [&] {
    return count(diagnostics(graph.run(), "camera"), "frames_labelled");
  };
  // Waits bound the test only (at most 60 s): the counts, not the speed, are checked.
  const auto wait_for_labelled = [&](std::int64_t above) {
    for (int i = 0; i < 6000 && labelled() <= above; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return labelled();
  };
  ASSERT_GT(wait_for_labelled(0), 0) << "the camera never locked";
  const auto dir = std::filesystem::temp_directory_path() /
                   ("avs_camera_param_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto out = dir / "out.txt";
  const auto err = dir / "err.txt";
  const auto avs = [&](std::vector<std::string> words) {
    return avs::testing::run_avs(std::move(words), out, err);
  };
  ASSERT_EQ(avs({"param", "set", "camera", "exposure_time_us", "2000"}), 0)
      << avs::testing::read_file(err);
  ASSERT_EQ(avs({"param", "set", "camera", "gain", "2"}), 0) << avs::testing::read_file(err);
  EXPECT_NE(avs::testing::read_file(out).find("/camera: gain = 2 (was -1)"), std::string::npos)
      << avs::testing::read_file(out);
  ASSERT_EQ(avs({"param", "set", "camera", "threshold_psi", "30"}), 0)
      << avs::testing::read_file(err);
  // The camera's own range, through the same checks as at start-up; the value stays 2.
  EXPECT_EQ(avs({"param", "set", "camera", "gain", "100000"}), 1);
  const std::string refusal = avs::testing::read_file(err);
  EXPECT_NE(refusal.find("= 100000 is out of range; the camera allows"), std::string::npos)
      << refusal;
  EXPECT_EQ(avs({"param", "get", "camera", "gain"}), 0) << avs::testing::read_file(err);
  EXPECT_EQ(avs::testing::read_file(out), "2\n");
  EXPECT_EQ(avs({"param", "set", "camera", "width", "256"}), 1);
  EXPECT_NE(avs::testing::read_file(err).find("width is not dynamic"), std::string::npos)
      << avs::testing::read_file(err);
  // Frames are still labelled after the changes (psi 30 still sees the stripes).
  const std::int64_t after_changes = labelled();
  EXPECT_GT(wait_for_labelled(after_changes + 2 * kBits), after_changes + 2 * kBits);
  EXPECT_EQ(graph.stop(), 0);
  std::filesystem::remove_all(dir);
}
#endif  // AVS_PROGRAM

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
