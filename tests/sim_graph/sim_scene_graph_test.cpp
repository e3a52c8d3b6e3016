// sim_scene + sim_amplifier in one sim-time lockstep container (issue 3 items 1, 5): a
// recorder in the same container checks the published frame sequence (bit, polarity, cycle,
// 1 ms stamps), the ground truth against the scene file and the head state, /timing, and
// that two runs (the second with a thread busy-looping on the other core) give identical
// ground truth and identical image checksums. DDS domain and Modbus ports leased per test
// process (tests/support/include/avs/testing/test_domain.hpp).
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "avs/geometry/head_kinematics.hpp"
#include "avs/graph/graph.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/testing/lockstep_graph.hpp"
#include "avs/testing/test_domain.hpp"

namespace avs::sim {
namespace {

using runtime::ComponentContext;
using runtime::ComponentSpec;

constexpr int kBits = 9;
constexpr int kFramesPerCycle = 2 * kBits;

struct FrameRecord {
  std::int64_t stamp_ns = 0;
  int bit_index = 0, bit_count = 0;
  bool positive = false;
  std::uint32_t cycle = 0;
  double pan_rad = 0, tilt_rad = 0;
  std::uint32_t width = 0, height = 0;
  std::string encoding;
  std::uint64_t checksum = 0;  ///< FNV-1a over the pixels
  bool operator==(const FrameRecord&) const = default;
};

struct TruthRecord {
  std::int64_t stamp_ns = 0;
  std::string name;
  Eigen::Isometry3d T_world_object, T_camera_object;
  double pan_rad = 0, tilt_rad = 0, pan_rate = 0, tilt_rate = 0;
  bool operator==(const TruthRecord& o) const {
    return stamp_ns == o.stamp_ns && name == o.name &&
           T_world_object.matrix() == o.T_world_object.matrix() &&
           T_camera_object.matrix() == o.T_camera_object.matrix() && pan_rad == o.pan_rad &&
           tilt_rad == o.tilt_rad && pan_rate == o.pan_rate && tilt_rate == o.tilt_rate;
  }
};

struct HeadRecord {
  std::int64_t stamp_ns = 0;
  double q[2] = {0, 0}, qd[2] = {0, 0};
};

Eigen::Isometry3d from_pose(const msgs::geometry_msgs::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  T.linear() =
      Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
          .toRotationMatrix();
  return T;
}

class TestSimRecorder final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {.type = "test_sim_recorder",
            .description = "tests: records sim_scene's and sim_amplifier's output",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern",
                                                                       keep_last_4),
                           runtime::port<msgs::avs_msgs::GroundTruth>("truth", "/sim/ground_truth"),
                           runtime::port<msgs::sensor_msgs::JointState>("head", "/sim/head_state"),
                           runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing")}};
  }

  explicit TestSimRecorder(ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::avs_msgs::PatternFrame>(
        "pattern", [this](runtime::SamplePtr<msgs::avs_msgs::PatternFrame> m) {
          FrameRecord r;
          r.stamp_ns = runtime::from_ros_time(m->header.stamp).ns;
          r.bit_index = m->bit_index;
          r.bit_count = m->bit_count;
          r.positive = m->positive;
          r.cycle = m->cycle;
          r.pan_rad = m->pan_rad;
          r.tilt_rad = m->tilt_rad;
          r.width = m->image.width;
          r.height = m->image.height;
          r.encoding = runtime::get_string(m->image.encoding);
          std::uint64_t h = 1469598103934665603ull;
          for (std::uint32_t i = 0; i < m->image.data._length; ++i) {
            h = (h ^ m->image.data._buffer[i]) * 1099511628211ull;
          }
          r.checksum = h;
          frames.push_back(r);
        });
    ctx.subscribe<msgs::avs_msgs::GroundTruth>(
        "truth", [this](runtime::SamplePtr<msgs::avs_msgs::GroundTruth> m) {
          truths.push_back({runtime::from_ros_time(m->header.stamp).ns,
                            std::string(runtime::get_string(m->object_name)),
                            from_pose(m->pose_world), from_pose(m->pose_camera), m->pan_rad,
                            m->tilt_rad, m->pan_velocity_rad_s, m->tilt_velocity_rad_s});
        });
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "head", [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) {
          HeadRecord r;
          r.stamp_ns = runtime::from_ros_time(m->header.stamp).ns;
          for (std::uint32_t i = 0; i < 2 && i < m->position._length; ++i) {
            r.q[i] = m->position._buffer[i];
            r.qd[i] = m->velocity._buffer[i];
          }
          heads.push_back(r);
        });
    ctx.subscribe<msgs::avs_msgs::StageTiming>(
        "timing", [this](runtime::SamplePtr<msgs::avs_msgs::StageTiming> m) {
          timing.emplace_back(runtime::from_ros_time(m->header.stamp).ns,
                              std::string(runtime::get_string(m->stage)));
          timing_ms.push_back(m->processing_ms);
        });
  }

  std::vector<FrameRecord> frames;
  std::vector<TruthRecord> truths;
  std::vector<HeadRecord> heads;
  std::vector<std::pair<std::int64_t, std::string>> timing;
  std::vector<double> timing_ms;
};

AVS_REGISTER_COMPONENT(TestSimRecorder);

/// Publishes /sim/head_state samples the renderer cannot use, one per `period_ms`: pan NaN,
/// tilt +inf, a NaN rate, no tilt joint, in turn (issue 20 section 2).
class TestBadHeadState final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {.type = "test_bad_head_state",
            .description = "tests: malformed /sim/head_state samples",
            .parameters = {},
            .publishes = {runtime::port<msgs::sensor_msgs::JointState>("head", "/sim/head_state")},
            .subscribes = {}};
  }
  explicit TestBadHeadState(ComponentContext& ctx)
      : Component(ctx), head_(ctx.publisher<msgs::sensor_msgs::JointState>("head")) {}
  void on_activate() override {
    context().create_timer(std::chrono::milliseconds(7), [this] { tick(); });
  }
  int sent = 0;

 private:
  void tick() {
    const int kind = sent % 4;
    auto m = runtime::make_sample<msgs::sensor_msgs::JointState>();
    runtime::to_ros_time(context().now(), m->header.stamp);
    const std::uint32_t n = kind == 3 ? 1 : 2;
    runtime::resize_sequence(m->name, n);
    runtime::resize_sequence(m->position, n);
    runtime::resize_sequence(m->velocity, n);
    runtime::set_string(m->name._buffer[0], "pan");
    if (n > 1) runtime::set_string(m->name._buffer[1], "tilt");
    const double nan = std::numeric_limits<double>::quiet_NaN();
    m->position._buffer[0] = kind == 0 ? nan : 0.1;
    if (n > 1) m->position._buffer[1] = kind == 1 ? std::numeric_limits<double>::infinity() : 0.1;
    m->velocity._buffer[0] = kind == 2 ? nan : 0.0;
    if (n > 1) m->velocity._buffer[1] = 0.0;
    head_.publish(std::move(m));
    ++sent;
  }
  runtime::Publisher<msgs::sensor_msgs::JointState> head_;
};

AVS_REGISTER_COMPONENT(TestBadHeadState);

struct GraphRun {
  std::unique_ptr<graph::Graph> graph;
  std::unique_ptr<runtime::Container> container;
  TestSimRecorder* recorder = nullptr;
  int status = -1;
};

/// Runs sim_amplifier + sim_scene + recorder for `duration_s` of sim time, lockstep; the
/// amplifier on `port` (default: this test's first port).
GraphRun run_graph(double duration_s, const std::string& scene_params,
                   const std::string& amplifier_params, int port = 0) {
  setenv("AVS_SOURCE_DIR", AVS_TEST_SOURCE_DIR, 1);
  if (port == 0) port = avs::testing::test_tcp_port(0);
  avs::testing::ContainerRun ran = avs::testing::run_lockstep_container(
      {"{type: sim_amplifier, name: amplifier, parameters: {port: " + std::to_string(port) +
           amplifier_params + "}}",
       "{type: sim_scene, name: scene, parameters: " + scene_params + "}",
       "{type: test_sim_recorder, name: recorder}"},
      duration_s);
  for (const auto& e : ran.load_errors) ADD_FAILURE() << e;
  GraphRun run;
  run.status = ran.status;
  run.recorder = ran.find<TestSimRecorder>("recorder");
  run.graph = std::move(ran.graph);
  run.container = std::move(ran.container);
  return run;
}

/// Swinging ken (launch_config/scenes/swing.yaml, already moving at frame 0) and a head
/// whose unbalanced tilt axis swings down from 0.3 rad: every frame has a new pose.
const std::string kSwingScene = "{scene: swing, start_time_s: 0.6, seed: 7}";
const std::string kFallingTilt =
    ", initial_pan_rad: 0.05, initial_tilt_rad: 0.3, "
    "tilt_gravity_nm: 3.0, watchdog_timeout_s: 0";
constexpr double kDurationS = 0.15;

TEST(SimSceneGraph, FramesCarryTheGrayCodeScheduleAndGroundTruthMatchesSceneAndHead) {
  const GraphRun run = run_graph(kDurationS, kSwingScene, kFallingTilt);
  ASSERT_EQ(run.status, 0);
  ASSERT_NE(run.recorder, nullptr);
  const auto& frames = run.recorder->frames;
  ASSERT_GE(frames.size(), 140u);
  ASSERT_LE(frames.size(), 151u);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const FrameRecord& f = frames[k];
    EXPECT_EQ(f.bit_index, static_cast<int>(k % kFramesPerCycle) / 2);
    EXPECT_EQ(f.positive, k % 2 == 0);
    EXPECT_EQ(f.cycle, k / kFramesPerCycle);
    EXPECT_EQ(f.bit_count, kBits);
    EXPECT_EQ(f.width, 512u);
    EXPECT_EQ(f.height, 512u);
    EXPECT_EQ(f.encoding, "mono8");
    if (k > 0) {
      EXPECT_EQ(f.stamp_ns - frames[k - 1].stamp_ns, 1'000'000) << "1000 fps";
    }
  }
  // Positive and negative of one bit differ; frames are not all the same.
  EXPECT_NE(frames[0].checksum, frames[1].checksum);

  // Ground truth: ken and wall per frame, same stamp; world pose = the scene file's
  // trajectory at start_time_s + k / 1000; camera pose = T_world_camera(q)^-1 x world pose.
  const SceneFile scene =
      load_scene(std::string(AVS_TEST_SOURCE_DIR) + "/launch_config/scenes/swing.yaml");
  const auto& truths = run.recorder->truths;
  ASSERT_EQ(truths.size(), 2 * frames.size());
  const auto& heads = run.recorder->heads;
  ASSERT_FALSE(heads.empty());
  int moving_tilt = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const double t_scene = 0.6 + static_cast<double>(k) / 1000.0;
    for (std::size_t i = 0; i < 2; ++i) {
      const TruthRecord& t = truths[2 * k + i];
      EXPECT_EQ(t.stamp_ns, frames[k].stamp_ns);
      EXPECT_EQ(t.name, scene.scene.objects[i].name);
      EXPECT_TRUE(t.T_world_object.isApprox(
          scene.scene.objects[i].trajectory->T_world_object(t_scene), 1e-12));
      const Eigen::Isometry3d T_world_camera =
          geometry::T_world_camera(scene.config.head, t.pan_rad, t.tilt_rad);
      EXPECT_TRUE(t.T_camera_object.isApprox(T_world_camera.inverse() * t.T_world_object, 1e-9));
      EXPECT_EQ(t.pan_rad, frames[k].pan_rad);
      EXPECT_EQ(t.tilt_rad, frames[k].tilt_rad);
    }
    // The angles are a /sim/head_state of the last 2 ms extrapolated to the frame time.
    const TruthRecord& t = truths[2 * k];
    bool matched = false;
    for (const HeadRecord& h : heads) {
      const std::int64_t age = frames[k].stamp_ns - h.stamp_ns;
      if (age < 0 || age > 2'000'000) continue;
      const double dt = static_cast<double>(age) * 1e-9;
      matched = matched || (std::abs(h.q[0] + h.qd[0] * dt - t.pan_rad) < 1e-12 &&
                            std::abs(h.q[1] + h.qd[1] * dt - t.tilt_rad) < 1e-12 &&
                            h.qd[0] == t.pan_rate && h.qd[1] == t.tilt_rate);
    }
    EXPECT_TRUE(matched) << "ground truth head angles not from a recent /sim/head_state";
    moving_tilt += std::abs(t.tilt_rate) > 0.01 ? 1 : 0;
  }
  EXPECT_GT(moving_tilt, 100) << "the test needs a moving head";
  EXPECT_NEAR(truths.front().pan_rad, 0.05, 1e-3);

  // /timing: one "render" per frame, same stamp.
  const auto& timing = run.recorder->timing;
  ASSERT_EQ(timing.size(), frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_EQ(timing[k].first, frames[k].stamp_ns);
    EXPECT_EQ(timing[k].second, "render");
    EXPECT_GT(run.recorder->timing_ms[k], 0.0);
  }
}

TEST(SimSceneGraph, MalformedHeadStatesAreRejectedCountedAndNeverRendered) {
  // Between the amplifier's good head states: NaN and infinite angles, a NaN rate and a state
  // without tilt. Before, a NaN pan went into the renderer's head pose and every frame after.
  setenv("AVS_SOURCE_DIR", AVS_TEST_SOURCE_DIR, 1);
  avs::testing::ContainerRun ran = avs::testing::run_lockstep_container(
      {"{type: sim_amplifier, name: amplifier, parameters: {port: " +
           std::to_string(avs::testing::test_tcp_port(0)) + "}}",
       "{type: test_bad_head_state, name: bad}",
       "{type: sim_scene, name: scene, parameters: " + kSwingScene + "}",
       "{type: test_sim_recorder, name: recorder}"},
      0.1);
  for (const auto& e : ran.load_errors) ADD_FAILURE() << e;
  ASSERT_EQ(ran.status, 0);
  const auto* bad = ran.find<TestBadHeadState>("bad");
  const auto* recorder = ran.find<TestSimRecorder>("recorder");
  ASSERT_NE(bad, nullptr);
  ASSERT_NE(recorder, nullptr);
  ASSERT_GE(bad->sent, 8);
  std::string rejected;
  for (const auto& [key, value] : ran.container->find_component("scene")->diagnostic_values()) {
    if (key == "rejected_samples") rejected = value;
  }
  // Every bad sample sent before the scene's last callback: all but possibly the last one.
  EXPECT_GE(std::stoi(rejected), bad->sent - 1);
  EXPECT_LE(std::stoi(rejected), bad->sent);
  ASSERT_FALSE(recorder->frames.empty());
  for (const FrameRecord& f : recorder->frames) {
    ASSERT_TRUE(std::isfinite(f.pan_rad) && std::isfinite(f.tilt_rad)) << f.stamp_ns;
  }
  for (const TruthRecord& t : recorder->truths) {
    ASSERT_TRUE(std::isfinite(t.pan_rad) && std::isfinite(t.tilt_rad)) << t.stamp_ns;
    ASSERT_TRUE(t.T_camera_object.matrix().allFinite()) << t.stamp_ns;
  }
}

TEST(SimSceneGraph, LockstepRunsAreIdenticalWithTheOtherCoreBusy) {
  const GraphRun quiet = run_graph(kDurationS, kSwingScene, kFallingTilt);
  std::atomic<bool> stop{false};
  std::thread busy([&stop] {
    volatile std::uint64_t x = 0;
    while (!stop.load(std::memory_order_relaxed)) x = x + 1;
  });
  // Each run's amplifier listens until its container is destroyed: other ports (135-136 of
  // our 130-139 range).
  const GraphRun loaded =
      run_graph(kDurationS, kSwingScene, kFallingTilt, avs::testing::test_tcp_port(1));
  stop = true;
  busy.join();
  ASSERT_EQ(quiet.status, 0);
  ASSERT_EQ(loaded.status, 0);
  ASSERT_NE(quiet.recorder, nullptr);
  ASSERT_NE(loaded.recorder, nullptr);
  ASSERT_GE(quiet.recorder->frames.size(), 140u);
  EXPECT_TRUE(quiet.recorder->frames == loaded.recorder->frames) << "frames or checksums differ";
  EXPECT_TRUE(quiet.recorder->truths == loaded.recorder->truths) << "ground truth differs";
  // A different seed changes the images (noise), not the ground truth.
  const GraphRun other = run_graph(kDurationS, "{scene: swing, start_time_s: 0.6, seed: 8}",
                                   kFallingTilt, avs::testing::test_tcp_port(2));
  ASSERT_NE(other.recorder, nullptr);
  ASSERT_EQ(other.recorder->frames.size(), quiet.recorder->frames.size());
  EXPECT_NE(other.recorder->frames[5].checksum, quiet.recorder->frames[5].checksum);
  EXPECT_TRUE(other.recorder->truths == quiet.recorder->truths);
}

TEST(SimSceneGraph, BuiltInSceneWithObjectTrajectoryAndDistanceOverrides) {
  // Built-in scene, the target replaced by the cube swinging at 2 m/s peak, 0.8 m away.
  const GraphRun run =
      run_graph(0.02,
                "{object: cube, trajectory: swing, swing_speed_m_s: 2.0, distance_m: 0.8, "
                "noise_sigma_dn: 0}",
                "");
  ASSERT_EQ(run.status, 0);
  ASSERT_NE(run.recorder, nullptr);
  const auto& truths = run.recorder->truths;
  ASSERT_GE(truths.size(), 2 * 19u);
  EXPECT_EQ(truths[0].name, "cube");
  EXPECT_EQ(truths[1].name, "wall");
  // Lateral swing along world Y about the start pose: x stays 0.8, speed at t = 0 is 2 m/s.
  for (std::size_t k = 0; k < truths.size(); k += 2) {
    EXPECT_NEAR(truths[k].T_world_object.translation().x(), 0.8, 1e-12);
  }
  const double dy =
      truths[2].T_world_object.translation().y() - truths[0].T_world_object.translation().y();
  EXPECT_NEAR(dy / 0.001, 2.0, 0.01);
  // Head at home: the cube is straight ahead, 0.8 m - a (40 mm) from the camera.
  EXPECT_NEAR(truths[0].T_camera_object.translation().z(), 0.76, 1e-9);
}

TEST(SimSceneGraph, UnknownSceneFailsTheContainerWithTheTriedPaths) {
  const GraphRun run = run_graph(0.01, "{scene: no_such_scene}", "");
  EXPECT_EQ(run.status, 1);
}

TEST(SimSceneGraph, SwingSpeedOnAStaticSceneIsAnError) {
  const GraphRun run = run_graph(0.01, "{scene: static_ken, swing_speed_m_s: 1.0}", "");
  EXPECT_EQ(run.status, 1);
}

}  // namespace
}  // namespace avs::sim
