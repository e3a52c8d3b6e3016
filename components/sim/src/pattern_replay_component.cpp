// pattern_replay: a recorded /camera/pattern stream handed to the graph at a fixed rate of
// the container clock, like a camera that does not wait (`avs bench pipeline`, issue 16).
// At construction it takes `recorded_frames` frames (whole Gray-code cycles) into memory:
// from an MCAP bag of /camera/pattern (`bag`: a recording of the closed loop, the head
// following the target, as a rig's camera sees it) or rendered from a scene with the head
// still at its home pose (`bag` empty). Once active it waits `start_delay_s`, then
// exposes one frame per slot of the absolute 1 / rate_hz grid from the first frame on (no
// drift). The recording is replayed cycle by cycle forwards, then backwards, and so on, so the
// target's motion stays continuous; `cycle` counts up throughout, so a receiver that checks
// the sequence (decode) sees one unbroken stream. Like the camera component (a GenICam camera
// streaming into a pool of `buffer_count` buffers, stamped with the exposure time), a frame
// is stamped with its slot's time and handed over at the first tick at or after it; a tick
// that comes late hands over every frame due since, oldest first (counted as late frames),
// and a frame older than the newest `buffer_count` slots is lost, as an overwritten buffer
// would be (counted as a missed slot). Each frame goes with a /head/joint_states sample (the
// recorded head angles) of the same stamp.
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

#include "avs/bag/bag_source.hpp"
#include "avs/geometry/frames.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/raw_topic.hpp"
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
            "takes whole Gray-code cycles from a bag of /camera/pattern (or renders them from a "
            "scene, head still) once, then replays them "
            "(forwards and backwards by cycle, cycle numbers counting up) on /camera/pattern and "
            "/head/joint_states at rate_hz on an absolute grid of the container clock, each "
            "frame stamped with its slot's time; a late tick hands over every frame due since "
            "(counted), frames beyond buffer_count are lost (counted) (avs bench pipeline)",
        .parameters =
            {ParamSpec::string("scene", "manipulator_ken",
                               "scene YAML (docs/sim.md), looked up as sim_scene's scene"),
             ParamSpec::integer("seed", 1, 0, 1e9, "", "sensor noise seed"),
             ParamSpec::string("bag", "",
                               "MCAP file with /camera/pattern (e.g. recorded from the closed "
                               "loop): its frames are replayed instead of rendered ones; empty: "
                               "render `scene`"),
             ParamSpec::real("start_time_s", 0.5, 0.0, 1e6, "s",
                             "scene time (bag: header stamp) of the first recorded frame; a bag "
                             "starts at the first cycle's first frame from this time on"),
             ParamSpec::integer("recorded_frames", 1008, 2, 100000, "",
                                "frames taken into memory, rendered or from the bag (rounded "
                                "down to whole cycles, at least one)"),
             ParamSpec::real("rate_hz", 1000.0, 1.0, 100000.0, "Hz", "replay frame rate"),
             ParamSpec::integer("buffer_count", 32, 1, 4096, "",
                                "frames exposed but not yet handed over that are kept (the "
                                "camera component's stream buffers); older ones are lost"),
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
                               "late_frames=N max_late_ms=X "
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
        buffer_count_(ctx.param<std::int64_t>("buffer_count")),
        wait_for_readers_(static_cast<std::size_t>(ctx.param<std::int64_t>("wait_for_readers"))),
        start_delay_(static_cast<std::int64_t>(ctx.param<double>("start_delay_s") * 1e9)),
        duration_ns_(static_cast<std::int64_t>(ctx.param<double>("duration_s") * 1e9)),
        report_file_(ctx.param<std::string>("report_file")) {
    if (const std::string bag = ctx.param<std::string>("bag"); bag.empty()) {
      record(ctx);
    } else {
      read_bag(ctx, bag);
    }
  }

  void on_activate() override {
    activated_ = context().now();
    context().create_timer(runtime::Duration(period_ns_), [this] { tick(); });
  }

  void on_deactivate() override {
    log().info("replayed ", published_, " frames (", negatives_, " negatives), ", late_frames_,
               " handed over late (at most ", 1e-6 * static_cast<double>(max_late_ns_),
               " ms after their slot), ", missed_slots_, " slots missed (more than ", buffer_count_,
               " frames behind)");
    if (report_file_.empty()) return;
    std::ofstream out(report_file_);
    out << "published=" << published_ << " negatives=" << negatives_
        << " missed_slots=" << missed_slots_ << " late_frames=" << late_frames_
        << " max_late_ms=" << 1e-6 * static_cast<double>(max_late_ns_)
        << " cpu_s=" << (cpu_last_s_ - cpu_first_s_)
        << " replay_s=" << 1e-9 * static_cast<double>((last_publish_ - first_slot_).count())
        << "\n";
    if (!out) log().error("cannot write ", report_file_);
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    std::lock_guard lock(mutex_);
    return {{"published", std::to_string(published_)},
            {"missed_slots", std::to_string(missed_slots_)},
            {"late_frames", std::to_string(late_frames_)}};
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

  /// Whole cycles of /camera/pattern from `file`: from the first frame that opens a cycle
  /// (bit 0, positive) stamped at or after start_time_s, without a gap in (cycle, bit,
  /// polarity), `recorded_frames` rounded down to whole cycles (fewer when the bag ends first).
  void read_bag(ComponentContext& ctx, const std::string& file) {
    const auto started = std::chrono::steady_clock::now();
    bag::BagStream stream(file, {"/camera/pattern"});
    const bag::ReplayChannel& channel = stream.channels().front();
    const std::string want = msg::TypeSupport<msgs::avs_msgs::PatternFrame>::dds_name;
    if (channel.type->dds_name != want) {
      throw runtime::Error(file + ": /camera/pattern is a " + channel.type->dds_name + ", not " +
                           want);
    }
    // Cyclone's serialiser of the type needs a participant (not used for anything else).
    const runtime::dds::Participant participant(ctx.dds_domain(), ctx.dds_partition());
    const runtime::dds::CdrCodec codec(participant, *channel.type);
    const std::int64_t start_ns = std::llround(ctx.param<double>("start_time_s") * 1e9);
    const std::int64_t wanted = ctx.param<std::int64_t>("recorded_frames");
    std::int64_t per_cycle = 0, target = 0;
    std::int64_t expected_cycle = -1, before_start = 0, frame_index = 0;
    while (auto message = stream.next()) {
      ++frame_index;
      const auto m = std::static_pointer_cast<const msgs::avs_msgs::PatternFrame>(
          std::shared_ptr<void>(codec.to_sample(message->data)));
      const std::int64_t stamp = runtime::from_ros_time(m->header.stamp).ns;
      if (frames_.empty()) {
        if (stamp < start_ns || m->bit_index != 0 || !m->positive) {
          ++before_start;
          continue;
        }
        if (m->bit_count < 1 || m->bit_count > 16) {
          throw runtime::Error(file + ": message " + std::to_string(frame_index) +
                               " of /camera/pattern has bit_count " + std::to_string(m->bit_count) +
                               " (expected 1-16)");
        }
        bit_count_ = m->bit_count;
        per_cycle = 2 * static_cast<std::int64_t>(bit_count_);
        target = std::max<std::int64_t>(1, wanted / per_cycle) * per_cycle;
        width_ = static_cast<int>(m->image.width);
        height_ = static_cast<int>(m->image.height);
        expected_cycle = m->cycle;
      }
      // The next frame must be the one after the last kept: (cycle, bit, polarity).
      const auto k = static_cast<std::int64_t>(frames_.size());
      const std::int64_t bit = (k % per_cycle) / 2;
      const bool positive = k % 2 == 0;
      const std::int64_t cycle = expected_cycle + k / per_cycle;
      if (m->cycle != cycle || m->bit_index != bit || m->positive != positive ||
          m->bit_count != bit_count_) {
        throw runtime::Error(file + ": message " + std::to_string(frame_index) +
                             " of /camera/pattern is cycle " + std::to_string(m->cycle) + " bit " +
                             std::to_string(m->bit_index) +
                             (m->positive ? " positive" : " negative") + ", expected cycle " +
                             std::to_string(cycle) + " bit " + std::to_string(bit) +
                             (positive ? " positive" : " negative") +
                             ": the recording has a gap (record it in lockstep)");
      }
      if (m->image.width != static_cast<std::uint32_t>(width_) ||
          m->image.height != static_cast<std::uint32_t>(height_) ||
          m->image.step != m->image.width ||
          m->image.data._length != m->image.width * m->image.height) {
        throw runtime::Error(file + ": message " + std::to_string(frame_index) +
                             " of /camera/pattern is not a " + std::to_string(width_) + " x " +
                             std::to_string(height_) + " mono8 image like the first");
      }
      PatternSlot pattern;
      pattern.bit_index = m->bit_index;
      pattern.positive = m->positive;
      frames_.push_back({std::vector<std::uint8_t>(m->image.data._buffer,
                                                   m->image.data._buffer + m->image.data._length),
                         pattern, m->pan_rad, m->tilt_rad});
      if (static_cast<std::int64_t>(frames_.size()) == target) break;
    }
    cycles_ = per_cycle == 0 ? 0 : static_cast<std::int64_t>(frames_.size()) / per_cycle;
    if (cycles_ < 1) {
      throw runtime::Error(file + ": no whole Gray-code cycle of /camera/pattern stamped at or " +
                           "after start_time_s = " + std::to_string(1e-9 * start_ns) + " s (" +
                           std::to_string(frame_index) + " frames read)");
    }
    frames_.resize(static_cast<std::size_t>(cycles_ * per_cycle));
    log().info("read ", frames_.size(), " frames (", cycles_, " cycles of ", per_cycle, ") of ",
               file, " from its frame ", before_start + 1, " (stamp >= ", 1e-9 * start_ns,
               " s) in ",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
               " s; replay at ", 1e9 / static_cast<double>(period_ns_), " Hz");
    if (cycles_ * per_cycle < target) {
      log().warn(file, " ends after ", frames_.size(),
                 " whole-cycle frames from the start, fewer "
                 "than the ",
                 target, " asked for");
    }
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
    // Every slot whose time has come (absolute grid from the first frame): the newest is
    // `due`; the ones since the last tick are handed over now, oldest first.
    std::int64_t due = since / period_ns_;
    if (duration_ns_ > 0) due = std::min(due, (duration_ns_ - 1) / period_ns_);
    std::int64_t next = last_slot_ + 1;
    std::int64_t missed = 0;
    if (due - next >= buffer_count_) {  // the oldest buffers were overwritten
      missed = due - next - buffer_count_ + 1;
      next += missed;
    }
    std::int64_t late = 0, max_late = 0;
    for (std::int64_t slot = next; slot <= due; ++slot) {
      const std::int64_t behind = since - slot * period_ns_;
      if (behind >= period_ns_) {
        ++late;
        max_late = std::max(max_late, behind);
      }
      publish(slot, first_slot_ + runtime::Duration(slot * period_ns_));
    }
    std::lock_guard lock(mutex_);
    missed_slots_ += missed;
    late_frames_ += late;
    max_late_ns_ = std::max(max_late_ns_, max_late);
    last_slot_ = std::max(last_slot_, due);
  }

  void publish(std::int64_t slot, runtime::Time exposed) {
    const std::int64_t per_cycle = 2 * bit_count_;
    const std::int64_t replay_cycle = slot / per_cycle;
    const Recorded& r = frames_[static_cast<std::size_t>(recorded_cycle(replay_cycle) * per_cycle +
                                                         slot % per_cycle)];
    auto m = pattern_.loan();  // every field set below
    runtime::set_string(m->header.frame_id, geometry::frame::kCameraOptical);
    auto& image = m->image;
    runtime::set_string(image.header.frame_id, geometry::frame::kCameraOptical);
    runtime::set_string(image.encoding, "mono8");
    image.width = static_cast<std::uint32_t>(width_);
    image.height = static_cast<std::uint32_t>(height_);
    image.step = image.width;
    image.is_bigendian = 0;
    runtime::resize_sequence(image.data, static_cast<std::uint32_t>(r.pixels.size()));
    std::copy(r.pixels.begin(), r.pixels.end(), image.data._buffer);
    m->bit_index = static_cast<std::uint8_t>(r.pattern.bit_index);
    m->bit_count = static_cast<std::uint8_t>(bit_count_);
    m->positive = r.pattern.positive;
    m->cycle = static_cast<std::uint32_t>(replay_cycle);
    m->pan_rad = r.pan_rad;
    m->tilt_rad = r.tilt_rad;

    auto joints = joints_.loan();  // every field set below (frame_id and effort stay empty)
    runtime::resize_sequence(joints->name, 2);
    runtime::resize_sequence(joints->position, 2);
    runtime::resize_sequence(joints->velocity, 2);
    runtime::set_string(joints->name._buffer[0], "pan");
    runtime::set_string(joints->name._buffer[1], "tilt");
    joints->position._buffer[0] = r.pan_rad;
    joints->position._buffer[1] = r.tilt_rad;
    joints->velocity._buffer[0] = joints->velocity._buffer[1] = 0.0;

    // Stamped with the slot's time (a camera's exposure stamp), at or before the hand-over:
    // the latency of everything downstream, a late hand-over included, counts from here.
    runtime::to_ros_time(exposed, m->header.stamp);
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
  const std::int64_t buffer_count_;
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
  std::int64_t late_frames_ = 0;
  std::int64_t max_late_ns_ = 0;
};

AVS_REGISTER_COMPONENT(PatternReplay);

}  // namespace avs::sim
