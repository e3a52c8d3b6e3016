// Issue 20 section 2, samples: one lockstep container holding decode, tracking and matching (as
// in closed_loop.yaml, where this container also carries the servo loop) and a hostile source
// that publishes every malformed sample the adversarial probe sent, between good joint states
// and good depth images. The container must run to its end, each component must reject and
// count what it cannot use (rejected_samples, /diagnostics WARN), log it without flooding, and
// no torque command or pose may carry a NaN.
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/rejections.hpp"
#include "avs/testing/diagnostics.hpp"
#include "avs/testing/lockstep_graph.hpp"
#include "avs/testing/test_domain.hpp"

namespace avs {
namespace {

using runtime::ComponentContext;
using runtime::ComponentSpec;

constexpr std::uint32_t kSide = 512;  // decode's default camera, which it sends on camera_info
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A malformed /camera/pattern frame (decode's input).
struct PatternCase {
  const char* what;
  std::uint8_t bit_index = 1;
  std::uint8_t bit_count = 9;
  const char* encoding = "mono8";
  std::uint32_t width = kSide, height = kSide, step = kSide, bytes = kSide * kSide;
};
const std::vector<PatternCase> kPatternCases = {
    {.what = "bit_index 200", .bit_index = 200},
    {.what = "bit_count 0", .bit_count = 0},
    {.what = "bit_count 16", .bit_count = 16},
    {.what = "bit_count 255", .bit_count = 255},
    {.what = "256x256 against a 512x512 camera",
     .width = 256,
     .height = 256,
     .step = 256,
     .bytes = 256 * 256},
    {.what = "rgb8", .encoding = "rgb8", .step = 3 * kSide, .bytes = 3 * kSide * kSide},
    {.what = "0x0", .width = 0, .height = 0, .step = 0, .bytes = 0},
    {.what = "short data", .bytes = 1000},
};

/// A malformed /depth/image (tracking's and matching's input).
struct DepthCase {
  const char* what;
  const char* encoding = "32FC1";
  std::uint8_t big_endian = 0;
  std::uint32_t width = kSide, height = kSide, step = 4 * kSide, bytes = 4 * kSide * kSide;
};
const std::vector<DepthCase> kDepthCases = {
    {.what = "0x0", .width = 0, .height = 0, .step = 0, .bytes = 0},
    {.what = "(2^30-1)x0", .width = (1u << 30) - 1, .height = 0, .step = 0, .bytes = 0},
    {.what = "(2^30-1)x1, step 4 (2^30-1)",
     .width = (1u << 30) - 1,
     .height = 1,
     .step = 4 * ((1u << 30) - 1),
     .bytes = 4096},
    {.what = "16UC1", .encoding = "16UC1", .step = 2 * kSide, .bytes = 2 * kSide * kSide},
    {.what = "big-endian", .big_endian = 1},
    {.what = "short data", .bytes = 1000},
    {.what = "256x256 against a 512x512 camera_info",
     .width = 256,
     .height = 256,
     .step = 4 * 256,
     .bytes = 4 * 256 * 256},
};

/// A /head/joint_states with one value not finite. Matching reads positions only.
struct JointCase {
  const char* what;
  double pan_rad = 0.0, tilt_rad = 0.0, pan_rad_s = 0.0;
  bool position_bad = true;
};
const std::vector<JointCase> kJointCases = {
    {.what = "pan NaN", .pan_rad = kNaN},
    {.what = "tilt +inf", .tilt_rad = kInf},
    {.what = "pan -inf", .pan_rad = -kInf},
    {.what = "pan velocity NaN", .pan_rad_s = kNaN, .position_bad = false},
};

std::int64_t joint_position_cases() {
  std::int64_t n = 0;
  for (const auto& c : kJointCases) n += c.position_bad ? 1 : 0;
  return n;
}

/// Every 1 ms: good joint states; every 10 ms a good depth image of a disc 1 m ahead, each of the
/// first ones just after a bad joint state; at 5 ms past every 10 the next bad pattern frame or
/// depth image. All bad samples are out by 0.16 s of the 1.05 s run.
class TestHostileSource final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {
        .type = "test_hostile_source",
        .description = "tests: malformed pattern frames, depth images and joint states",
        .parameters = {},
        .publishes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern"),
                      runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image"),
                      runtime::port<msgs::sensor_msgs::JointState>("joints", "/head/joint_states")},
        .subscribes = {}};
  }
  explicit TestHostileSource(ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        depth_(ctx.publisher<msgs::sensor_msgs::Image>("depth")),
        joints_(ctx.publisher<msgs::sensor_msgs::JointState>("joints")) {}
  void on_activate() override {
    context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  std::int64_t last_bad_ns = 0;  ///< stamp of the last bad sample sent

 private:
  void tick() {
    const runtime::Time now = context().now();
    const std::uint64_t k = tick_++;
    if (k % 10 == 0 && next_joint_ < kJointCases.size()) {
      const JointCase& c = kJointCases[next_joint_++];
      publish_joints(now, c.pan_rad, c.tilt_rad, c.pan_rad_s);
      last_bad_ns = now.ns;
    } else {
      publish_joints(now, 0.01, -0.02, 0.0);
    }
    if (k % 10 == 0) publish_good_depth(now);
    if (k % 10 != 5) return;
    if (next_pattern_ < kPatternCases.size()) {
      publish_bad_pattern(now, kPatternCases[next_pattern_++]);
      last_bad_ns = now.ns;
    } else if (next_depth_ < kDepthCases.size()) {
      publish_bad_depth(now, kDepthCases[next_depth_++]);
      last_bad_ns = now.ns;
    }
  }

  void publish_joints(runtime::Time now, double pan_rad, double tilt_rad, double pan_rad_s) {
    auto js = runtime::make_sample<msgs::sensor_msgs::JointState>();
    runtime::to_ros_time(now, js->header.stamp);
    runtime::resize_sequence(js->name, 2);
    runtime::set_string(js->name._buffer[0], "pan");
    runtime::set_string(js->name._buffer[1], "tilt");
    runtime::resize_sequence(js->position, 2);
    js->position._buffer[0] = pan_rad;
    js->position._buffer[1] = tilt_rad;
    runtime::resize_sequence(js->velocity, 2);
    js->velocity._buffer[0] = pan_rad_s;
    js->velocity._buffer[1] = 0.0;
    joints_.publish(std::move(js));
  }

  void publish_good_depth(runtime::Time now) {
    auto m = runtime::make_sample<msgs::sensor_msgs::Image>();
    runtime::to_ros_time(now, m->header.stamp);
    runtime::set_string(m->encoding, "32FC1");
    m->width = m->height = kSide;
    m->step = 4 * kSide;
    runtime::resize_sequence(m->data, m->step * m->height);
    auto* z = reinterpret_cast<float*>(m->data._buffer);
    for (std::uint32_t v = 0; v < kSide; ++v) {
      for (std::uint32_t u = 0; u < kSide; ++u) {
        const double du = u - 280.0, dv = v - 240.0;  // a disc off centre: tracking turns
        z[v * kSide + u] =
            du * du + dv * dv < 40.0 * 40.0 ? 1.0f : std::numeric_limits<float>::quiet_NaN();
      }
    }
    depth_.publish(std::move(m));
  }

  void publish_bad_pattern(runtime::Time now, const PatternCase& c) {
    auto m = runtime::make_sample<msgs::avs_msgs::PatternFrame>();
    runtime::to_ros_time(now, m->header.stamp);
    m->bit_index = c.bit_index;
    m->bit_count = c.bit_count;
    m->positive = true;
    runtime::set_string(m->image.encoding, c.encoding);
    m->image.width = c.width;
    m->image.height = c.height;
    m->image.step = c.step;
    runtime::resize_sequence(m->image.data, c.bytes);
    pattern_.publish(std::move(m));
  }

  void publish_bad_depth(runtime::Time now, const DepthCase& c) {
    auto m = runtime::make_sample<msgs::sensor_msgs::Image>();
    runtime::to_ros_time(now, m->header.stamp);
    runtime::set_string(m->encoding, c.encoding);
    m->is_bigendian = c.big_endian;
    m->width = c.width;
    m->height = c.height;
    m->step = c.step;
    runtime::resize_sequence(m->data, c.bytes);
    depth_.publish(std::move(m));
  }

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  runtime::Publisher<msgs::sensor_msgs::Image> depth_;
  runtime::Publisher<msgs::sensor_msgs::JointState> joints_;
  std::uint64_t tick_ = 0;
  std::size_t next_pattern_ = 0, next_depth_ = 0, next_joint_ = 0;
};

/// Counts torque commands and poses, and those with a value that is not finite.
class TestCommandWatch final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {
        .type = "test_command_watch",
        .description = "tests: counts torque commands and poses, and non-finite ones",
        .parameters = {},
        .publishes = {},
        .subscribes = {
            runtime::port<msgs::avs_msgs::JointTorqueCommand>("command", "/head/torque_command"),
            runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose")}};
  }
  explicit TestCommandWatch(ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::avs_msgs::JointTorqueCommand>(
        "command", [this](runtime::SamplePtr<msgs::avs_msgs::JointTorqueCommand> m) {
          ++commands;
          last_command_ns = runtime::from_ros_time(m->header.stamp).ns;
          bool finite = m->torque_nm._length == 2;
          for (double t : runtime::as_span(m->torque_nm)) finite = finite && std::isfinite(t);
          if (!finite) ++bad_commands;
          if (finite && m->torque_nm._buffer[0] != 0.0) ++nonzero_commands;
        });
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) {
          ++poses;
          const auto& p = m->pose;
          const double values[] = {p.position.x,    p.position.y,    p.position.z,
                                   p.orientation.x, p.orientation.y, p.orientation.z,
                                   p.orientation.w};
          for (double v : values) {
            if (!std::isfinite(v)) {
              ++bad_poses;
              break;
            }
          }
        });
  }
  int commands = 0, bad_commands = 0, nonzero_commands = 0, poses = 0, bad_poses = 0;
  std::int64_t last_command_ns = 0;
};

AVS_REGISTER_COMPONENT(TestHostileSource);
AVS_REGISTER_COMPONENT(TestCommandWatch);

std::int64_t rejected(const runtime::Component& c) {
  for (const auto& [key, value] : c.diagnostic_values()) {
    if (key == "rejected_samples") return std::stoll(value);
  }
  ADD_FAILURE() << "no rejected_samples among the diagnostic values";
  return -1;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(BadSamples, EveryMalformedSampleIsRejectedCountedAndNoNaNReachesACommand) {
  // /diagnostics as a monitor sees it: a reader in another participant.
  const runtime::dds::Participant participant(avs::testing::test_domain());
  using Array = msgs::diagnostic_msgs::DiagnosticArray;
  const runtime::dds::Topic topic(participant, msg::TypeSupport<Array>::descriptor(),
                                  "rt/diagnostics", runtime::QosProfile{});
  const runtime::dds::Reader reader(participant, topic, runtime::QosProfile{});

  ::testing::internal::CaptureStderr();
  const avs::testing::ContainerRun run = avs::testing::run_lockstep_container(
      {"{type: test_hostile_source, name: source}", "{type: decode, name: decode}",
       "{type: tracking, name: tracking}", "{type: matching, name: matching}",
       "{type: test_command_watch, name: watch}"},
      1.05);
  const std::string err = ::testing::internal::GetCapturedStderr();
  for (const auto& e : run.load_errors) ADD_FAILURE() << e;
  ASSERT_NE(run.container, nullptr);
  EXPECT_EQ(run.status, 0) << "the container did not run to its end\n" << err;

  const auto* source = run.find<TestHostileSource>("source");
  const auto* watch = run.find<TestCommandWatch>("watch");
  const auto* decode = run.find<runtime::Component>("decode");
  const auto* tracking = run.find<runtime::Component>("tracking");
  const auto* matching = run.find<runtime::Component>("matching");
  ASSERT_TRUE(source && watch && decode && tracking && matching);

  // Each malformed sample counted once by each component that reads it.
  const auto pattern_cases = static_cast<std::int64_t>(kPatternCases.size());
  const auto depth_cases = static_cast<std::int64_t>(kDepthCases.size());
  const auto joint_cases = static_cast<std::int64_t>(kJointCases.size());
  EXPECT_EQ(rejected(*decode), pattern_cases);
  EXPECT_EQ(rejected(*tracking), depth_cases + joint_cases);
  EXPECT_EQ(rejected(*matching), depth_cases + joint_position_cases());

  // Rate-limited log: the first SampleRejections::kLoggedFirst of decode's eight, then silence.
  EXPECT_EQ(count_of(err, "/camera/pattern frame rejected"),
            static_cast<std::size_t>(runtime::SampleRejections::kLoggedFirst))
      << err;
  EXPECT_NE(err.find("bit_count 255"), std::string::npos) << err;
  EXPECT_NE(err.find("1073741823x0"), std::string::npos) << err;

  // The good depth images around the bad samples still gave commands, none of them NaN, and
  // the loop went on after the last bad sample.
  EXPECT_GE(watch->commands, 100);
  EXPECT_EQ(watch->bad_commands, 0);
  EXPECT_GT(watch->nonzero_commands, 0) << "tracking never turned toward the disc";
  EXPECT_GT(watch->last_command_ns, source->last_bad_ns + 500'000'000);
  EXPECT_EQ(watch->bad_poses, 0);

  // /diagnostics at t = 1 s: each component active, WARN for the samples it rejected.
  std::map<std::string, int> statuses;
  avs::testing::take_diagnostic_statuses(reader, "", [&](const auto& status) {
    const std::string name(runtime::get_string(status.name));
    const std::string component = name.substr(name.find('/') + 1);
    if (component != "decode" && component != "tracking" && component != "matching") return;
    SCOPED_TRACE(name);
    ++statuses[component];
    EXPECT_EQ(status.level, 1) << runtime::get_string(status.message);
    EXPECT_NE(std::string(runtime::get_string(status.message)).find("rejecting input samples"),
              std::string::npos)
        << runtime::get_string(status.message);
    std::map<std::string, std::string> values;
    for (const auto& kv : runtime::as_span(status.values)) {
      values[std::string(runtime::get_string(kv.key))] = runtime::get_string(kv.value);
    }
    EXPECT_EQ(values["state"], "active");
    EXPECT_EQ(values["rejected_samples"],
              std::to_string(rejected(*run.find<runtime::Component>(component))));
  });
  // One report in 1.05 s of sim time, after every bad sample.
  EXPECT_EQ(statuses,
            (std::map<std::string, int>{{"decode", 1}, {"matching", 1}, {"tracking", 1}}));
}

}  // namespace
}  // namespace avs
