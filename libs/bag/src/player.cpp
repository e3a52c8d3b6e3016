#include "avs/bag/player.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <set>
#include <thread>

#include "avs/bag/bag_source.hpp"
#include "avs/bag/qos_yaml.hpp"
#include "avs/mcap/reader.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/topic_name.hpp"
#include "rosgraph_msgs.h"

namespace avs::bag {

namespace {

using runtime::Error;
namespace dds = runtime::dds;
using SteadyClock = std::chrono::steady_clock;

struct ChannelPlan {
  dds::RawWriter* writer = nullptr;  // null: not played
  std::string published_as;
};

/// Paced publishing: maps bag log time to wall time, minus pauses, divided by the rate.
class Pacer {
 public:
  Pacer(const PlayOptions& o, const PlayControl& c, mcap::Timestamp bag_start, double duration_s,
        dds::Writer* clock_writer)
      : options_(o),
        control_(c),
        bag_start_(bag_start),
        duration_s_(duration_s),
        clock_(clock_writer) {}

  void begin_pass(int pass) {
    pass_ = pass;
    wall_start_ = SteadyClock::now();
    paused_total_ = {};
    last_clock_ = 0;
    gap_skipped_ns_ = 0;
    previous_ = bag_start_;
  }

  /// Gaps above max_gap_s shortened so far.
  std::uint64_t gaps_shortened() const { return gaps_shortened_; }

  bool stopped() const { return control_.stop != nullptr && control_.stop->load(); }

  /// Waits until `t` is due (publishing /clock and progress meanwhile); false when stopped.
  bool wait_until(mcap::Timestamp t, std::uint64_t published) {
    published_ = published;
    shorten_gap(t);
    for (;;) {
      if (stopped()) return false;
      const bool paused = control_.paused != nullptr && control_.paused->load();
      const auto now = SteadyClock::now();
      if (paused) {
        const auto pause_start = now;
        report(now, true);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        paused_total_ += SteadyClock::now() - pause_start;
        continue;
      }
      const mcap::Timestamp current = bag_time_at(now);
      publish_clock(std::min(current, t));
      report(now, false);
      if (current >= t) return true;
      const double wait_s = static_cast<double>(t - current) * 1e-9 / options_.rate;
      const double step =
          std::min({wait_s, 0.05, options_.clock ? options_.clock_period_s / options_.rate : 0.05});
      if (step > 0.0005) {
        std::this_thread::sleep_for(std::chrono::duration<double>(step));
      } else if (step > 0) {
        std::this_thread::yield();
      }
    }
  }

  /// A gap from the previous message above max_gap_s is cut to max_gap_s: the pacing skips
  /// the rest (told on stderr, the first few times).
  void shorten_gap(mcap::Timestamp t) {
    const auto max_gap_ns = static_cast<mcap::Timestamp>(options_.max_gap_s * 1e9);
    if (t > previous_ && t - previous_ > max_gap_ns) {
      const mcap::Timestamp cut = t - previous_ - max_gap_ns;
      if (++gaps_shortened_ <= 5) {
        std::fprintf(stderr,
                     "avs bag play: %.3f s without a message before log time %llu ns (a corrupt "
                     "log_time?): waiting %.3f s instead (--max-gap)%s\n",
                     static_cast<double>(t - previous_) * 1e-9, static_cast<unsigned long long>(t),
                     options_.max_gap_s, gaps_shortened_ == 5 ? "; not saying this again" : "");
      }
      gap_skipped_ns_ += cut;
    }
    previous_ = std::max(previous_, t);
  }

  void publish_clock(mcap::Timestamp t) {
    if (clock_ == nullptr || t <= last_clock_) return;
    if (t - last_clock_ < static_cast<mcap::Timestamp>(options_.clock_period_s * 1e9) &&
        last_clock_ != 0) {
      return;
    }
    force_clock(t);
  }

  /// /clock exactly at a message's time, before the message (sim-time graphs see the
  /// sample no earlier than its time).
  void force_clock(mcap::Timestamp t) {
    if (clock_ == nullptr || t <= last_clock_) return;
    rosgraph_msgs_msg_dds__Clock_ sample{};
    runtime::to_ros_time(runtime::Time{static_cast<std::int64_t>(t)}, sample.clock);
    clock_->write(&sample);
    last_clock_ = t;
  }

  void report(SteadyClock::time_point now, bool paused) {
    if (!control_.on_progress || now - last_report_ < std::chrono::milliseconds(100)) return;
    last_report_ = now;
    PlayProgress p;
    p.bag_time_s = static_cast<double>(bag_time_at(now) - bag_start_) * 1e-9;
    p.duration_s = duration_s_;
    p.published = published_;
    p.paused = paused;
    p.pass = pass_;
    control_.on_progress(p);
  }

 private:
  mcap::Timestamp bag_time_at(SteadyClock::time_point now) const {
    const double elapsed = std::chrono::duration<double>(now - wall_start_ - paused_total_).count();
    return bag_start_ + gap_skipped_ns_ +
           static_cast<mcap::Timestamp>(std::max(0.0, elapsed) * options_.rate * 1e9);
  }

  const PlayOptions& options_;
  const PlayControl& control_;
  mcap::Timestamp bag_start_;
  double duration_s_;
  dds::Writer* clock_;
  SteadyClock::time_point wall_start_{};
  SteadyClock::duration paused_total_{};
  SteadyClock::time_point last_report_{};
  mcap::Timestamp last_clock_ = 0;
  std::uint64_t published_ = 0;
  int pass_ = 0;
  mcap::Timestamp previous_ = 0;        // the last message's log time (bag_start at first)
  mcap::Timestamp gap_skipped_ns_ = 0;  // bag time cut out of long gaps this pass
  std::uint64_t gaps_shortened_ = 0;
};

/// Says, and keeps in `result`, each corrupt chunk the reader left out.
void report_skipped_chunks(const std::filesystem::path& file,
                           const std::vector<mcap::SkippedChunk>& chunks, PlayResult& result) {
  for (const auto& chunk : chunks) {
    std::fprintf(stderr, "avs bag play: %s: skipped the corrupt chunk at offset %llu: %s\n",
                 file.string().c_str(), static_cast<unsigned long long>(chunk.offset),
                 chunk.problem.c_str());
    result.skipped_chunks.push_back("offset " + std::to_string(chunk.offset) + ": " +
                                    chunk.problem);
  }
}

}  // namespace

PlayResult play(const PlayOptions& o, const PlayControl& control) {
  if (!(o.rate > 0)) throw Error("avs bag play: --rate must be > 0");
  if (!(o.max_gap_s > 0)) throw Error("avs bag play: --max-gap must be > 0");
  mcap::Reader reader;
  PlayResult result;
  const OpenedBag opened = open_bag(reader, o.file, "avs bag play");
  const bool truncated = opened.truncated;
  report_skipped_chunks(o.file, opened.skipped_chunks, result);
  const mcap::Summary& summary = reader.summary();
  mcap::Timestamp start = 0, end = 0;
  if (summary.statistics) {
    start = summary.statistics->message_start_time;
    end = summary.statistics->message_end_time;
  } else if (!summary.chunk_indexes.empty()) {
    start = ~mcap::Timestamp{0};
    for (const auto& c : summary.chunk_indexes) {
      if (c.message_start_time == 0 && c.message_end_time == 0) continue;
      start = std::min(start, c.message_start_time);
      end = std::max(end, c.message_end_time);
    }
    if (end == 0) start = 0;
  }
  const mcap::Timestamp bag_start =
      start + static_cast<mcap::Timestamp>(std::max(0.0, o.start_offset_s) * 1e9);
  const double duration_s = static_cast<double>(end - std::min(end, start)) * 1e-9;

  std::set<std::string> wanted;
  for (const auto& t : o.topics) wanted.insert(ros_topic_name(t));
  std::map<std::string, std::string> remaps;
  for (const auto& [from, to] : o.remaps) remaps[ros_topic_name(from)] = ros_topic_name(to);

  dds::Participant participant(o.domain, o.partition);
  std::map<std::string, std::unique_ptr<dds::RawWriter>> writers;  // by published ROS name
  std::map<mcap::ChannelId, ChannelPlan> plans;
  std::set<std::string> read_topics;
  const ChannelSelection selection = select_channels(summary, wanted);
  for (const auto& why : selection.skipped) {
    result.skipped.push_back(why);
    std::fprintf(stderr, "avs bag play: NOT playing %s\n", why.c_str());
  }
  for (const ReplayChannel& channel : selection.channels) {
    std::string out = channel.topic;
    if (auto r = remaps.find(channel.topic); r != remaps.end()) out = r->second;
    auto& w = writers[out];
    if (!w) {
      w = std::make_unique<dds::RawWriter>(
          participant, *channel.type, runtime::to_dds_topic_name(out), replay_qos(channel.offered));
    }
    plans[channel.id] = {w.get(), out};
    read_topics.insert(channel.topic);
  }
  if (plans.empty()) throw Error("avs bag play: " + o.file.string() + ": no topic to play");

  std::unique_ptr<dds::Topic> clock_topic;
  std::unique_ptr<dds::Writer> clock_writer;
  if (o.clock) {
    const runtime::QosProfile clock_qos = *runtime::QosProfile::named("clock");
    clock_topic = std::make_unique<dds::Topic>(participant, &rosgraph_msgs_msg_dds__Clock__desc,
                                               "rt/clock", clock_qos);
    clock_writer = std::make_unique<dds::Writer>(participant, *clock_topic, clock_qos);
  }
  if (o.delay_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(o.delay_s));

  Pacer pacer(o, control, bag_start, duration_s, clock_writer.get());
  mcap::ReadOptions ro;
  ro.start_time = bag_start;
  ro.topics = read_topics;
  ro.allow_truncated = truncated;
  for (int pass = 0;; ++pass) {
    pacer.begin_pass(pass);
    std::string write_error;
    mcap::ReadReport read_report;
    const mcap::Status s = reader.read_messages(
        [&](const mcap::MessageView& m) {
          auto plan = plans.find(m.channel->id);
          if (plan == plans.end()) return true;
          if (!pacer.wait_until(m.log_time, result.published)) return false;
          pacer.force_clock(m.log_time);
          try {
            plan->second.writer->write(m.data);
          } catch (const std::exception& e) {
            write_error = e.what();
            return false;
          }
          ++result.published;
          ++result.per_topic[plan->second.published_as];
          return true;
        },
        ro, &read_report);
    // A scan at open has said its skipped chunks already; the chunk indexes' are said once.
    if (pass == 0 && read_report.used_summary) {
      report_skipped_chunks(o.file, read_report.skipped_chunks, result);
    }
    result.gaps_shortened = pacer.gaps_shortened();
    if (!write_error.empty()) throw Error("avs bag play: " + write_error);
    if (!s.ok()) throw Error("avs bag play: " + o.file.string() + ": " + s.to_string());
    if (!o.loop || pacer.stopped()) break;
  }
  return result;
}

}  // namespace avs::bag
