// bag_player: publishes the messages of a bag inside a graph at the times they had in the
// recording, so that a lockstep graph reprocessing a bag sees every sample at the simulated
// time it saw live, in the recorded order, whatever the machine's load (docs/bag.md). The
// timing is libs/bag's ReplaySchedule, the reading its BagStream.
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "avs/bag/bag_source.hpp"
#include "avs/bag/qos_yaml.hpp"
#include "avs/bag/replay_schedule.hpp"
#include "avs/msg/convert.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::bag {
namespace {

using runtime::ParamSpec;

class BagPlayerComponent final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {
        .type = "bag_player",
        .description =
            "publishes a bag's messages inside the graph at their recorded times (header stamp, "
            "else log time); in lockstep sim time the graph reprocesses it exactly",
        .parameters =
            {ParamSpec::string("file", "", "the MCAP file to play (required)"),
             ParamSpec::string("topics", "",
                               "comma-separated topics to play (ROS names); empty: every topic"),
             ParamSpec::string("time", "header",
                               "header: a message with a std_msgs/Header is due at its stamp, "
                               "one without at its log time moved onto the stamps' time line; "
                               "log: every message at its log time",
                               {"header", "log"}),
             ParamSpec::boolean("stop_at_end", true,
                                "stop the container linger_s after the last message"),
             ParamSpec::real("linger_s", 0.01, 0.0, 3600.0, "s",
                             "time given to the graph after the last message before stopping")},
        .open_ports = true,
    };
  }

  explicit BagPlayerComponent(runtime::ComponentContext& ctx)
      : Component(ctx),
        schedule_(ctx.param<std::string>("time") == "log" ? ReplaySchedule::Clock::log
                                                          : ReplaySchedule::Clock::header),
        stop_at_end_(ctx.param<bool>("stop_at_end")),
        linger_(static_cast<std::int64_t>(ctx.param<double>("linger_s") * 1e9)),
        rejected_(ctx.log(), "bag message") {
    const std::string file = ctx.param<std::string>("file");
    if (file.empty()) throw runtime::Error("bag_player: parameter 'file' is required");
    const std::string topics = ctx.param<std::string>("topics");
    stream_ = std::make_unique<BagStream>(
        file, topics.empty() ? std::vector<std::string>{} : msg::parse_name_list(topics, 0, "topics"));
    for (const auto& why : stream_->skipped_channels()) log().warn("NOT playing ", why);
    for (const ReplayChannel& c : stream_->channels()) {
      publishers_.push_back(
          ctx.serialized_publisher(c.topic, c.type->dds_name, replay_qos(c.offered).to_profile()));
    }
    log().info("playing ", stream_->channels().size(), " topic(s) of ", file, " (time: ",
               ctx.param<std::string>("time"), ")");
  }

  void on_activate() override {
    start_ = context().now();
    advance();
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    return {{"published", std::to_string(published_)}, rejected_.diagnostic()};
  }

 private:
  /// Publishes every message that is due, then waits (a timer) for the next one.
  void advance() {
    for (;;) {
      if (!pending_) {
        std::optional<StreamedMessage> m;
        try {
          m = stream_->next();
        } catch (const std::exception& e) {
          log().error(e.what(), " (stopping at the last message read)");
        }
        if (!m) {
          finish();
          return;
        }
        const ReplayChannel& c = stream_->channels()[m->channel];
        const std::optional<std::int64_t> stamp =
            c.has_header ? header_stamp_ns(m->data) : std::nullopt;
        due_ = to_container_time(
            schedule_.due_ns(static_cast<std::int64_t>(m->log_time), stamp));
        pending_ = std::move(m);
      }
      const runtime::Time now = context().now();
      if (due_ > now) {
        wait_for(due_ - now, [this] { advance(); });
        return;
      }
      try {
        publishers_[pending_->channel]->publish(pending_->data);
        ++published_;
      } catch (const std::exception& e) {
        rejected_.reject(e.what());
      }
      pending_.reset();
    }
  }

  /// A recording's time as this container's: the same in simulated time (the recording's
  /// stamps are the sim time the graph had); in wall time shifted so the first message is
  /// due at activation.
  runtime::Time to_container_time(std::int64_t due_ns) {
    if (due_ns == ReplaySchedule::kAtOnce) return runtime::Time{0};
    if (context().uses_sim_time()) return runtime::Time{due_ns};
    if (!wall_offset_ns_) wall_offset_ns_ = start_.ns - due_ns;
    return runtime::Time{due_ns + *wall_offset_ns_};
  }

  /// Runs `fn` once, `delay` from now (a timer cancelled at its first tick).
  void wait_for(runtime::Duration delay, std::function<void()> fn) {
    timer_ = context().create_timer(std::max(delay, runtime::Duration(1)),
                                    [this, fn = std::move(fn)] {
                                      context().cancel_timer(timer_);
                                      fn();
                                    });
  }

  void finish() {
    log().info("end of the bag: ", published_, " message(s) published, ", rejected_.count(),
               " rejected");
    for (const auto& chunk : stream_->skipped_chunks()) log().warn("skipped corrupt chunk ", chunk);
    if (!stop_at_end_) return;
    wait_for(linger_, [this] {
      context().request_stop("bag_player reached the end of its bag");
    });
  }

  std::unique_ptr<BagStream> stream_;
  std::vector<std::shared_ptr<runtime::SerializedPublisher>> publishers_;
  ReplaySchedule schedule_;
  const bool stop_at_end_;
  const runtime::Duration linger_;
  runtime::SampleRejections rejected_;
  runtime::Time start_{};
  std::optional<std::int64_t> wall_offset_ns_;
  std::optional<StreamedMessage> pending_;
  runtime::Time due_{};
  runtime::TimerId timer_ = 0;
  std::uint64_t published_ = 0;
};

AVS_REGISTER_COMPONENT(BagPlayerComponent);

}  // namespace
}  // namespace avs::bag
