// Issue 16 section 3, in a container: a sample published by one component and delivered to
// another on the same lane (the intra-process path every frame takes: publish, the lane's queue,
// the subscription's callback), and a timer's tick, allocate nothing after warm-up (the source
// reuses one sample, so what is counted is the container's); and the decode, tracking, matching
// and servo drive components' whole callbacks, fed rendered frames, allocate nothing either.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/runtime/scheduler.hpp"
#include "avs/testing/lockstep_graph.hpp"
#include "avs/testing/test_domain.hpp"
#include "ken_recording.hpp"

namespace avs::testing {
namespace {

constexpr int kWarmUpTicks = 100;
constexpr int kCountedTicks = 1000;
constexpr int kWarmUpFrames = 108;  // 6 cycles: every buffer has reached its working size
constexpr int kCountedFrames = 1000;

/// Counting runs from the start of a tick to the end of the sink's callback for the sample the
/// tick published: the timer, publish, the queue and the delivery, and nothing else the lane
/// does (the container's 1 Hz diagnostics, the lockstep clock's /clock).
std::atomic<long> g_deliveries{0};

class AllocSource final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_source",
            .description =
                "publishes one reused std_msgs/Float64 every 1 ms, counting "
                "allocations from its tick to the sink's delivery",
            .parameters = {},
            .publishes = {runtime::port<msgs::std_msgs::Float64>("out", "alloc_probe")},
            .subscribes = {}};
  }
  explicit AllocSource(runtime::ComponentContext& ctx)
      : Component(ctx),
        out_(ctx.publisher<msgs::std_msgs::Float64>("out")),
        sample_(runtime::make_sample<msgs::std_msgs::Float64>()) {}
  void on_activate() override {
    timer_ = context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  long ticks = 0;
  long counted = -1;  ///< allocations over the counted ticks (-1: not reached)

 private:
  void tick() {
    ++ticks;
    if (ticks == kWarmUpTicks) reset_counted_allocations();
    if (ticks == kWarmUpTicks + kCountedTicks) counted = counted_allocations();
    const bool counting = ticks >= kWarmUpTicks && ticks < kWarmUpTicks + kCountedTicks;
    count_allocations_on_this_thread(counting);
    sample_->data = static_cast<double>(ticks);
    out_.publish(sample_);
  }

  runtime::Publisher<msgs::std_msgs::Float64> out_;
  std::shared_ptr<msgs::std_msgs::Float64> sample_;
  runtime::TimerId timer_{};
};

class AllocSink final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_sink",
            .description = "counts the samples it gets and ends the allocation count",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::std_msgs::Float64>("in", "alloc_probe")}};
  }
  explicit AllocSink(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::std_msgs::Float64>("in", [](runtime::SamplePtr<msgs::std_msgs::Float64>) {
      g_deliveries.fetch_add(1);
      count_allocations_on_this_thread(false);
    });
  }
};

AVS_REGISTER_COMPONENT(AllocSource);
AVS_REGISTER_COMPONENT(AllocSink);

/// The decode and tracking components' hot paths in their container: the recording's frames
/// published on /camera/pattern (loaned samples, stamped 1 ms apart) with the head's joint
/// states, and a marker behind each positive frame. Counting runs from the tick to the sink's
/// delivery of the marker (a positive frame: decode's callback ran before it) or of the depth
/// map (a negative frame: the sink comes after tracking in the graph, so decode's callback,
/// and tracking's for that depth map, ran before it): the rolling update, sub-code refinement,
/// moments and servo law, and every sample they fill and publish.
class PatternSource final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {
        .type = "test_alloc_pattern_source",
        .description =
            "publishes the rendered ken frames every 1 ms, each followed by a "
            "marker that ends the allocation count",
        .parameters = {},
        .publishes = {runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern"),
                      runtime::port<msgs::sensor_msgs::JointState>("joints", "/head/joint_states"),
                      runtime::port<msgs::std_msgs::Float64>("marker", "alloc_marker")},
        .subscribes = {}};
  }
  explicit PatternSource(runtime::ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        joints_(ctx.publisher<msgs::sensor_msgs::JointState>("joints")),
        marker_(ctx.publisher<msgs::std_msgs::Float64>("marker")) {}
  void on_activate() override {
    timer_ = context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  long frames = 0;
  long counted = -1;  ///< allocations over the counted frames (-1: not reached)

 private:
  void tick() {
    if (frames == kWarmUpFrames) reset_counted_allocations();
    if (frames == kWarmUpFrames + kCountedFrames) counted = counted_allocations();
    count_allocations_on_this_thread(frames >= kWarmUpFrames &&
                                     frames < kWarmUpFrames + kCountedFrames);
    const decode::PatternFrame f = recording().frame(static_cast<int>(frames));
    auto joints = joints_.loan();
    runtime::to_ros_time(context().now(), joints->header.stamp);
    runtime::resize_sequence(joints->name, 2);
    runtime::resize_sequence(joints->position, 2);
    runtime::resize_sequence(joints->velocity, 2);
    runtime::set_string(joints->name._buffer[0], "pan");
    runtime::set_string(joints->name._buffer[1], "tilt");
    joints->position._buffer[0] = joints->position._buffer[1] = 0.0;
    joints->velocity._buffer[0] = joints->velocity._buffer[1] = 0.0;
    joints_.publish(std::move(joints));
    auto m = pattern_.loan();
    runtime::to_ros_time(context().now(), m->header.stamp);
    runtime::set_string(m->header.frame_id, "camera_optical");
    m->image.header.stamp = m->header.stamp;
    runtime::set_string(m->image.header.frame_id, "camera_optical");
    runtime::set_string(m->image.encoding, "mono8");
    m->image.width = static_cast<std::uint32_t>(f.image.width);
    m->image.height = static_cast<std::uint32_t>(f.image.height);
    m->image.step = m->image.width;
    m->image.is_bigendian = 0;
    const auto bytes = static_cast<std::uint32_t>(f.image.width * f.image.height);
    runtime::resize_sequence(m->image.data, bytes);
    std::copy_n(f.image.data, bytes, m->image.data._buffer);
    m->bit_index = static_cast<std::uint8_t>(f.bit_index);
    m->bit_count = static_cast<std::uint8_t>(recording().per_cycle / 2);
    m->positive = f.polarity == decode::Polarity::kPositive;
    m->cycle = f.cycle;
    m->pan_rad = m->tilt_rad = 0.0;
    const bool positive = m->positive;
    pattern_.publish(std::move(m));
    if (positive) {
      auto marker = marker_.loan();
      marker->data = static_cast<double>(frames);
      marker_.publish(std::move(marker));
    }
    ++frames;
  }

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  runtime::Publisher<msgs::sensor_msgs::JointState> joints_;
  runtime::Publisher<msgs::std_msgs::Float64> marker_;
  runtime::TimerId timer_{};
};

/// Ends the count at each marker and each depth map, and counts the depth maps and torque
/// commands.
class MarkerSink final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_marker_sink",
            .description = "ends the allocation count at each marker; counts depth maps",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::std_msgs::Float64>("marker", "alloc_marker"),
                           runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image"),
                           runtime::port<msgs::avs_msgs::JointTorqueCommand>(
                               "command", "/head/torque_command")}};
  }
  explicit MarkerSink(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::std_msgs::Float64>("marker",
                                           [](runtime::SamplePtr<msgs::std_msgs::Float64>) {
                                             count_allocations_on_this_thread(false);
                                           });
    ctx.subscribe<msgs::sensor_msgs::Image>("depth",
                                            [this](runtime::SamplePtr<msgs::sensor_msgs::Image>) {
                                              ++depth_maps;
                                              count_allocations_on_this_thread(false);
                                            });
    ctx.subscribe<msgs::avs_msgs::JointTorqueCommand>(
        "command", [this](runtime::SamplePtr<msgs::avs_msgs::JointTorqueCommand>) { ++commands; });
  }
  long depth_maps = 0;
  long commands = 0;
};

AVS_REGISTER_COMPONENT(PatternSource);
AVS_REGISTER_COMPONENT(MarkerSink);

/// Ends the count at each marker and each /object/match (matching publishes one per depth map,
/// after its pose, world pose, timing and clouds); counts the matches and the tracked ones.
class MatchSink final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_match_sink",
            .description = "ends the allocation count at each marker and match; counts them",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::std_msgs::Float64>("marker", "alloc_marker"),
                           runtime::port<msgs::avs_msgs::MatchResult>("match", "/object/match")}};
  }
  explicit MatchSink(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::std_msgs::Float64>("marker",
                                           [](runtime::SamplePtr<msgs::std_msgs::Float64>) {
                                             count_allocations_on_this_thread(false);
                                           });
    ctx.subscribe<msgs::avs_msgs::MatchResult>(
        "match", [this](runtime::SamplePtr<msgs::avs_msgs::MatchResult> m) {
          ++matches;
          if (m->state == avs_msgs_msg_dds__MatchResult_Constants_STATE_TRACKING) ++tracked;
          count_allocations_on_this_thread(false);
        });
  }
  long matches = 0;
  long tracked = 0;
};

AVS_REGISTER_COMPONENT(MatchSink);

/// The servo drive component's cycle in its container: a torque command every 1 ms (loaned),
/// the drive's Modbus TCP exchange with both axes of sim_amplifier (its server answers on a
/// thread of its own, not counted), safety rules, and the joint states and drive status it
/// publishes. Graph order amplifier, source, drive, sink: at each instant the amplifier's plant
/// step runs first (the simulator, not counted), then the source's tick arms the count, the
/// drive takes the command and cycles, and the sink's delivery of the joint states ends it.
class CommandSource final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_command_source",
            .description =
                "publishes a small sinusoidal torque command every 1 ms and arms the "
                "allocation count",
            .parameters = {},
            .publishes = {runtime::port<msgs::avs_msgs::JointTorqueCommand>(
                "command", "/head/torque_command")},
            .subscribes = {}};
  }
  explicit CommandSource(runtime::ComponentContext& ctx)
      : Component(ctx), command_(ctx.publisher<msgs::avs_msgs::JointTorqueCommand>("command")) {}
  void on_activate() override {
    timer_ = context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  long ticks = 0;
  long counted = -1;  ///< allocations over the counted cycles (-1: not reached)

 private:
  void tick() {
    if (ticks == kWarmUpTicks) reset_counted_allocations();
    if (ticks == kWarmUpTicks + kCountedTicks) counted = counted_allocations();
    count_allocations_on_this_thread(ticks >= kWarmUpTicks && ticks < kWarmUpTicks + kCountedTicks);
    auto m = command_.loan();
    runtime::to_ros_time(context().now(), m->header.stamp);
    runtime::resize_sequence(m->name, 2);
    runtime::resize_sequence(m->torque_nm, 2);
    runtime::set_string(m->name._buffer[0], "pan");
    runtime::set_string(m->name._buffer[1], "tilt");
    const double t = static_cast<double>(ticks) * 1e-3;
    m->torque_nm._buffer[0] = 0.05 * std::sin(2 * M_PI * t);
    m->torque_nm._buffer[1] = 0.01 * std::sin(2 * M_PI * t);
    command_.publish(std::move(m));
    ++ticks;
  }

  runtime::Publisher<msgs::avs_msgs::JointTorqueCommand> command_;
  runtime::TimerId timer_{};
};

/// Ends the count at each joint state; counts them.
class JointStateSink final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_joint_state_sink",
            .description = "ends the allocation count at each joint state; counts them",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::sensor_msgs::JointState>("joint_states",
                                                                        "/head/joint_states")}};
  }
  explicit JointStateSink(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states", [this](runtime::SamplePtr<msgs::sensor_msgs::JointState>) {
          ++joint_states;
          count_allocations_on_this_thread(false);
        });
  }
  long joint_states = 0;
};

AVS_REGISTER_COMPONENT(CommandSource);
AVS_REGISTER_COMPONENT(JointStateSink);

void count_delivery(const void* context, const std::shared_ptr<const void>&, std::uint64_t) {
  ++*static_cast<long*>(const_cast<void*>(context));
}

// The scheduler alone, everything its lane thread does counted (the container tests above count
// from a callback to a callback, so the scheduler's own work between them is checked here):
// re-arming the timer, posting a delivery, popping it, waiting and advancing lockstep time.
TEST(ContainerAllocations, SchedulerTicksAndDeliveriesAllocateNothingAfterWarmUp) {
  runtime::Scheduler scheduler(runtime::TimeMode::sim_lockstep);
  const int lane = scheduler.add_lane();
  const auto sample = std::make_shared<const int>(7);
  long ticks = 0;
  long delivered = 0;
  long counted = -1;
  scheduler.add_timer(lane, std::chrono::milliseconds(1), [&] {
    if (ticks == kWarmUpTicks) {
      reset_counted_allocations();
      count_allocations_on_this_thread(true);
    }
    if (ticks == kWarmUpTicks + kCountedTicks) {
      count_allocations_on_this_thread(false);
      counted = counted_allocations();
      scheduler.stop();
    }
    ++ticks;
    scheduler.post(lane, &count_delivery, &delivered, sample, static_cast<std::uint64_t>(ticks));
  });
  scheduler.run_lane(lane);  // on this thread, until stop()
  count_allocations_on_this_thread(false);
  EXPECT_GE(delivered, kWarmUpTicks + kCountedTicks);
  EXPECT_EQ(counted, 0) << "allocations over " << kCountedTicks << " ticks and deliveries";
}

TEST(ContainerAllocations, PublishDeliverAndTimerTicksAllocateNothingAfterWarmUp) {
  const ContainerRun run = run_lockstep_container(
      {"{type: test_alloc_source, name: source}", "{type: test_alloc_sink, name: sink}"},
      (kWarmUpTicks + kCountedTicks + 50) * 1e-3);
  ASSERT_EQ(run.status, 0);
  const auto* source = run.find<AllocSource>("source");
  ASSERT_NE(source, nullptr);
  ASSERT_GE(source->ticks, kWarmUpTicks + kCountedTicks);
  EXPECT_GE(g_deliveries.load(), kWarmUpTicks + kCountedTicks);  // the path really ran
  EXPECT_EQ(source->counted, 0) << "allocations over " << kCountedTicks
                                << " ticks, each a publish and a delivery";
}

TEST(ContainerAllocations, DecodeAndTrackingComponentsAllocateNothingPerFrameAfterWarmUp) {
  const ContainerRun run = run_lockstep_container(
      {"{type: test_alloc_pattern_source, name: source}",
       "{type: decode, name: decode, parameters: {subcode_half_window: 4}}",
       "{type: tracking, name: tracking}", "{type: test_alloc_marker_sink, name: sink}"},
      (kWarmUpFrames + kCountedFrames + 20) * 1e-3);
  ASSERT_EQ(run.status, 0) << (run.load_errors.empty() ? "" : run.load_errors.front());
  const auto* source = run.find<PatternSource>("source");
  const auto* sink = run.find<MarkerSink>("sink");
  ASSERT_NE(source, nullptr);
  ASSERT_NE(sink, nullptr);
  ASSERT_GE(source->frames, kWarmUpFrames + kCountedFrames);
  // Both really ran: a depth map per pair, a torque command per depth map.
  EXPECT_GE(sink->depth_maps, (kWarmUpFrames + kCountedFrames) / 2 - 20);
  EXPECT_GE(sink->commands, sink->depth_maps - 1);
  EXPECT_EQ(source->counted, 0) << "allocations over " << kCountedFrames
                                << " frames through the decode and tracking components";
}

// The matching component with closed_loop.yaml's parameters (clouds published too), fed by
// decode: counted from each frame's publish to the delivery of its /object/match, so decode's
// callback is inside the count as well.
TEST(ContainerAllocations, MatchingComponentAllocatesNothingPerDepthMapAfterWarmUp) {
  const ContainerRun run = run_lockstep_container(
      {"{type: test_alloc_pattern_source, name: source}",
       "{type: decode, name: decode, parameters: {subcode_half_window: 4}}",
       "{type: matching, name: matching, parameters: {model: ken, publish_scene_points: true, "
       "publish_model_points: true, lag_compensation_s: 0.009, velocity_window_s: 0.03, "
       "icp_model: dense, icp_max_distance_m: 0.015, scene_points: 500, scene_voxel_m: 0.005, "
       "outlier_neighbours: 8, icp_iterations: [0, 0, 2], reacquire_within_s: 0.05}}",
       "{type: test_alloc_match_sink, name: sink}"},
      (kWarmUpFrames + kCountedFrames + 20) * 1e-3);
  ASSERT_EQ(run.status, 0) << (run.load_errors.empty() ? "" : run.load_errors.front());
  const auto* source = run.find<PatternSource>("source");
  const auto* sink = run.find<MatchSink>("sink");
  ASSERT_NE(source, nullptr);
  ASSERT_NE(sink, nullptr);
  ASSERT_GE(source->frames, kWarmUpFrames + kCountedFrames);
  // It really matched: a result per depth map, and the ken tracked in most of them.
  EXPECT_GE(sink->matches, (kWarmUpFrames + kCountedFrames) / 2 - 20);
  EXPECT_GT(sink->tracked, kCountedFrames / 4);
  EXPECT_EQ(source->counted, 0) << "allocations over " << kCountedFrames
                                << " frames through the decode and matching components";
}

TEST(ContainerAllocations, ServoDriveComponentAllocatesNothingPerCycleAfterWarmUp) {
  const std::string port = std::to_string(test_tcp_port(0));
  const ContainerRun run = run_lockstep_container(
      {"{type: sim_amplifier, name: amplifier, parameters: {port: " + port +
           ", plant_rate_hz: 1000}}",
       "{type: test_alloc_command_source, name: source}",
       "{type: servo_drive, name: drive, parameters: {port: " + port + ", cycle_rate_hz: 1000}}",
       "{type: test_alloc_joint_state_sink, name: sink}"},
      (kWarmUpTicks + kCountedTicks + 20) * 1e-3);
  ASSERT_EQ(run.status, 0) << (run.load_errors.empty() ? "" : run.load_errors.front());
  const auto* source = run.find<CommandSource>("source");
  const auto* sink = run.find<JointStateSink>("sink");
  ASSERT_NE(source, nullptr);
  ASSERT_NE(sink, nullptr);
  ASSERT_GE(source->ticks, kWarmUpTicks + kCountedTicks);
  EXPECT_GE(sink->joint_states, kWarmUpTicks + kCountedTicks);  // the drive really cycled
  EXPECT_EQ(source->counted, 0) << "allocations over " << kCountedTicks
                                << " cycles of the servo drive component";
}

}  // namespace
}  // namespace avs::testing
