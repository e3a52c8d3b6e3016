// pattern_replay: a recorded /camera/pattern stream handed to the graph at a fixed rate of
// the container clock, like a camera that does not wait (`avs bench pipeline`, issue 16).
// At construction it renders `recorded_frames` frames of a scene (whole Gray-code cycles,
// the head still at its home pose) into memory; once active it waits `start_delay_s`, then
// publishes one frame per slot of the absolute 1 / rate_hz grid from the first frame on (no
// drift). The recording is replayed cycle by cycle forwards, then backwards, and so on, so the
// target's motion stays continuous; `cycle` counts up throughout, so a receiver that checks
// the sequence (decode) sees one unbroken stream. A slot whose tick came too late for it is
// counted as a missed slot (the frame it would have shown is skipped, as a camera would
// expose it anyway), never sent late in its place. Each frame goes with a
// /head/joint_states sample (the recorded head angles) of the same stamp; the stamp is the
// clock just before the frame is handed over.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "avs/geometry/frames.hpp"
#include "avs/runtime/component.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/simulator.hpp"
#include "scene_path.hpp"

namespace avs::sim {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

namespace {

double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

class PatternReplay final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {
        .type = "pattern_replay",
        .description =
            "renders whole Gray-code cycles of a scene once (head still), then replays them "
            "(forwards and backwards by cycle, cycle numbers counting up) on /camera/pattern and "
            "/head/joint_states at rate_hz on an absolute grid of the container clock; late "
            "slots are counted, not sent late (avs bench pipeline)",
        .parameters =
            {ParamSpec::string("scene", "manipulator_ken",
                               "scene YAML (docs/sim.md), looked up as sim_scene's scene"),
             ParamSpec::integer("seed", 1, 0, 1e9, "", "sensor noise seed"),
             ParamSpec::real("start_time_s", 0.5, 0.0, 1e6, "s",
                             "scene time of the first recorded frame"),
             ParamSpec::integer("recorded_frames", 1008, 2, 100000, "",
                                "frames rendered into memory (rounded down to whole cycles, at "
                                "least one)"),
             ParamSpec::real("rate_hz", 1000.0, 1.0, 100000.0, "Hz", "replay frame rate"),
             ParamSpec::integer("wait_for_readers", 0, 0, 1000, "",
                                "before the start delay, wait until /camera/pattern has this "
                                "many readers (in this container or matched over DDS)"),
             ParamSpec::real("start_delay_s", 1.0, 0.0, 3600.0, "s",
                             "clock time after activation (and the readers) before the first "
                             "frame: discovery, the other components' activation"),
             ParamSpec::real("duration_s", 0.0, 0.0, 1e6, "s",
                             "replay for this long, then stop publishing; 0: until stopped"),
             ParamSpec::string("report_file", "",
                               "on deactivate, write 'published=N negatives=N missed_slots=N "
                               "cpu_s=S replay_s=S' to this file (benchmarks; cpu_s: this "
                               "process's CPU time from the first frame to the last)")},
        .publishes = {
            runtime::port<msgs::avs_msgs::PatternFrame>("pattern", "/camera/pattern", keep_last_4),
            runtime::port<msgs::sensor_msgs::JointState>("joint_states", "/head/joint_states")}};
  }

  explicit PatternReplay(ComponentContext& ctx)
      : Component(ctx),
        pattern_(ctx.publisher<msgs::avs_msgs::PatternFrame>("pattern")),
        joints_(ctx.publisher<msgs::sensor_msgs::JointState>("joint_states")),
        period_ns_(static_cast<std::int64_t>(std::llround(1e9 / ctx.param<double>("rate_hz")))),
        wait_for_readers_(static_cast<std::size_t>(ctx.param<std::int64_t>("wait_for_readers"))),
        start_delay_(static_cast<std::int64_t>(ctx.param<double>("start_delay_s") * 1e9)),
        duration_ns_(static_cast<std::int64_t>(ctx.param<double>("duration_s") * 1e9)),
        report_file_(ctx.param<std::string>("report_file")) {
    record(ctx);
  }

  void on_activate() override {
    activated_ = context().now();
    context().create_timer(runtime::Duration(period_ns_), [this] { tick(); });
  }

  void on_deactivate() override {
    log().info("replayed ", published_, " frames (", negatives_, " negatives), ", missed_slots_,
               " slots missed (the tick came after the slot's end)");
    if (report_file_.empty()) return;
    std::ofstream out(report_file_);
    out << "published=" << published_ << " negatives=" << negatives_
        << " missed_slots=" << missed_slots_ << " cpu_s=" << (cpu_last_s_ - cpu_first_s_)
        << " replay_s=" << 1e-9 * static_cast<double>((last_publish_ - first_slot_).count())
        << "\n";
    if (!out) log().error("cannot write ", report_file_);
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    std::lock_guard lock(mutex_);
    return {{"published", std::to_string(published_)},
            {"missed_slots", std::to_string(missed_slots_)}};
  }

 private:
  struct Recorded {
    std::vector<std::uint8_t> pixels;
    PatternSlot pattern;
    double pan_rad = 0;
    double tilt_rad = 0;
  };

  void record(ComponentContext& ctx) {
    SceneFile file = load_scene(resolve_scene_path(ctx.param<std::string>("scene")));
    file.config.renderer.noise_seed = static_cast<std::uint64_t>(ctx.param<std::int64_t>("seed"));
    Simulator sim(std::move(file.config), std::move(file.scene));
    bit_count_ = sim.config().renderer.geometry.layout.bit_count;
    const std::int64_t per_cycle = 2 * bit_count_;
    cycles_ = std::max<std::int64_t>(1, ctx.param<std::int64_t>("recorded_frames") / per_cycle);
    const double t0 = ctx.param<double>("start_time_s");
    const auto started = std::chrono::steady_clock::now();
    const HeadState head;
    for (std::int64_t k = 0; k < cycles_ * per_cycle; ++k) {
      const auto index = static_cast<std::uint64_t>(k);
      SimFrame f = sim.render(index, t0 + sim.frame_time_s(index), head);
      width_ = f.image.width;
      height_ = f.image.height;
      frames_.push_back(
          {std::move(f.image.pixels), f.pattern, f.truth.head.pan_rad, f.truth.head.tilt_rad});
    }
    log().info("recorded ", frames_.size(), " frames (", cycles_, " cycles of ", per_cycle, ") of ",
               ctx.param<std::string>("scene"), " from t = ", t0, " s in ",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
               " s; replay at ", 1e9 / static_cast<double>(period_ns_), " Hz");
  }

  /// The recorded cycle shown in replay cycle `r`: 0, 1, .., C-1, C-2, .., 1, 0, 1, ...
  std::int64_t recorded_cycle(std::int64_t r) const {
    if (cycles_ <= 1) return 0;
    const std::int64_t p = r % (2 * (cycles_ - 1));
    return p < cycles_ ? p : 2 * (cycles_ - 1) - p;
  }

  void tick() {
    const runtime::Time now = context().now();
    if (!started_) {
      if (pattern_.reader_count() < wait_for_readers_) {
        activated_ = now;  // the start delay counts from the readers' arrival
        return;
      }
      if ((now - activated_).count() < start_delay_) return;
      first_slot_ = now;
      cpu_first_s_ = process_cpu_s();
      started_ = true;
    }
    const std::int64_t since = (now - first_slot_).count();
    if (duration_ns_ > 0 && since >= duration_ns_) return;
    // The slot this tick belongs to on the absolute grid from the first frame.
    std::int64_t slot = since / period_ns_;
    if (slot <= last_slot_) slot = last_slot_ + 1;
    const std::int64_t missed = last_slot_ < 0 ? slot : slot - last_slot_ - 1;
    publish(slot);
    std::lock_guard lock(mutex_);
    missed_slots_ += missed;
    last_slot_ = slot;
  }

  void publish(std::int64_t slot) {
    const std::int64_t per_cycle = 2 * bit_count_;
    const std::int64_t replay_cycle = slot / per_cycle;
    const Recorded& r = frames_[static_cast<std::size_t>(recorded_cycle(replay_cycle) * per_cycle +
                                                         slot % per_cycle)];
    auto m = runtime::make_sample<msgs::avs_msgs::PatternFrame>();
    runtime::set_string(m->header.frame_id, geometry::frame::kCameraOptical);
    auto& image = m->image;
    runtime::set_string(image.header.frame_id, geometry::frame::kCameraOptical);
    runtime::set_string(image.encoding, "mono8");
    image.width = static_cast<std::uint32_t>(width_);
    image.height = static_cast<std::uint32_t>(height_);
    image.step = image.width;
    runtime::resize_sequence(image.data, static_cast<std::uint32_t>(r.pixels.size()));
    std::copy(r.pixels.begin(), r.pixels.end(), image.data._buffer);
    m->bit_index = static_cast<std::uint8_t>(r.pattern.bit_index);
    m->bit_count = static_cast<std::uint8_t>(bit_count_);
    m->positive = r.pattern.positive;
    m->cycle = static_cast<std::uint32_t>(replay_cycle);
    m->pan_rad = r.pan_rad;
    m->tilt_rad = r.tilt_rad;

    auto joints = runtime::make_sample<msgs::sensor_msgs::JointState>();
    runtime::resize_sequence(joints->name, 2);
    runtime::resize_sequence(joints->position, 2);
    runtime::resize_sequence(joints->velocity, 2);
    runtime::set_string(joints->name._buffer[0], "pan");
    runtime::set_string(joints->name._buffer[1], "tilt");
    joints->position._buffer[0] = r.pan_rad;
    joints->position._buffer[1] = r.tilt_rad;
    joints->velocity._buffer[0] = joints->velocity._buffer[1] = 0.0;

    // Stamped at the hand-over: the latency of everything downstream is measured from here.
    runtime::to_ros_time(context().now(), m->header.stamp);
    image.header.stamp = m->header.stamp;
    joints->header.stamp = m->header.stamp;
    joints_.publish(std::move(joints));
    pattern_.publish(std::move(m));
    last_publish_ = context().now();
    cpu_last_s_ = process_cpu_s();
    std::lock_guard lock(mutex_);
    ++published_;
    if (!r.pattern.positive) ++negatives_;
  }

  runtime::Publisher<msgs::avs_msgs::PatternFrame> pattern_;
  runtime::Publisher<msgs::sensor_msgs::JointState> joints_;
  const std::int64_t period_ns_;
  const std::size_t wait_for_readers_;
  const std::int64_t start_delay_;
  const std::int64_t duration_ns_;
  const std::string report_file_;
  std::vector<Recorded> frames_;
  int bit_count_ = 9;
  int width_ = 0;
  int height_ = 0;
  std::int64_t cycles_ = 1;
  runtime::Time activated_{};
  runtime::Time first_slot_{};
  runtime::Time last_publish_{};
  double cpu_first_s_ = 0;
  double cpu_last_s_ = 0;
  bool started_ = false;
  std::int64_t last_slot_ = -1;
  mutable std::mutex mutex_;
  std::int64_t published_ = 0;
  std::int64_t negatives_ = 0;
  std::int64_t missed_slots_ = 0;
};

AVS_REGISTER_COMPONENT(PatternReplay);

}  // namespace avs::sim
