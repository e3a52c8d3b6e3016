// avs bag record | play | info | repair: MCAP bags of serialised topics (docs/bag.md).
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <thread>

#include "avs/bag/player.hpp"
#include "avs/bag/recorder.hpp"
#include "avs/mcap/info.hpp"
#include "avs/mcap/reader.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/error.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"
#include "live_view.hpp"

namespace avs::cli {

namespace {

std::string human_bytes(double bytes) {
  char buf[32];
  if (bytes >= 1e9) {
    std::snprintf(buf, sizeof buf, "%.2f GB", bytes / 1e9);
  } else if (bytes >= 1e6) {
    std::snprintf(buf, sizeof buf, "%.1f MB", bytes / 1e6);
  } else {
    std::snprintf(buf, sizeof buf, "%.0f kB", bytes / 1e3);
  }
  return buf;
}

// ---- record -------------------------------------------------------------------------------

struct RecordArgs {
  bag::RecordOptions options;
  std::string compression = "zstd";
  double duration_s = 0;
  double queue_mb = 1024;
};

int run_record(RecordArgs& a) {
  auto compression = mcap::parse_compression(a.compression);
  if (!compression) {
    std::cerr << "avs bag record: --compression must be zstd, lz4 or none, not '" << a.compression
              << "'\n";
    return 2;
  }
  a.options.compression = *compression;
  a.options.queue_bytes = static_cast<std::uint64_t>(a.queue_mb * 1e6);
  stop_on_interrupt();
  bag::Recorder recorder(a.options);
  recorder.start();
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  bag::RecorderStatus previous = recorder.status();
  while (!stop_requested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto now = std::chrono::steady_clock::now();
    if (a.duration_s > 0 && now - start >= std::chrono::duration<double>(a.duration_s)) break;
    if (now - last < std::chrono::milliseconds(500)) continue;
    const bag::RecorderStatus s = recorder.status();
    if (s.finished) break;
    if (tty) {
      const double dt = std::chrono::duration<double>(now - last).count();
      std::fprintf(
          stderr,
          "\r\033[Krecording %zu topics | %.0f msg/s | %.1f MB/s | lost %llu | queue %s | %s in %s",
          s.topics.size(), static_cast<double>(s.received - previous.received) / dt,
          static_cast<double>(s.bytes_received - previous.bytes_received) / dt / 1e6,
          static_cast<unsigned long long>(s.lost),
          human_bytes(static_cast<double>(s.queue_bytes)).c_str(),
          human_bytes(static_cast<double>(s.file_bytes)).c_str(),
          s.files.empty() ? "" : s.files.back().filename().string().c_str());
    }
    previous = s;
    last = now;
  }
  if (tty) std::fprintf(stderr, "\r\033[K");
  int status = 0;
  try {
    recorder.stop();
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    status = 1;
  }
  const bag::RecorderStatus s = recorder.status();
  std::cout << bag::format_record_report(s);
  if (status == 0 && s.lost > 0) {
    std::cerr << "avs bag record: " << s.lost << " message(s) LOST (see above)\n";
    status = 3;
  }
  return status;
}

// ---- play ---------------------------------------------------------------------------------

/// Puts the terminal in non-canonical, no-echo mode while alive (space = pause/resume).
class RawTerminal {
 public:
  RawTerminal() {
    if (isatty(STDIN_FILENO) == 0 || tcgetattr(STDIN_FILENO, &saved_) != 0) return;
    termios raw = saved_;
    raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
  }
  ~RawTerminal() {
    if (active_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;
  bool active() const { return active_; }

 private:
  termios saved_{};
  bool active_ = false;
};

struct PlayArgs {
  bag::PlayOptions options;
  std::vector<std::string> remaps;
  LiveViewFlags view;
};

int run_play(PlayArgs& a) {
  for (const auto& r : a.remaps) {
    const auto sep = r.find(":=");
    if (sep == std::string::npos || sep == 0 || sep + 2 == r.size()) {
      std::cerr << "avs bag play: --remap wants FROM:=TO, got '" << r << "'\n";
      return 2;
    }
    a.options.remaps[r.substr(0, sep)] = r.substr(sep + 2);
  }
  // Before the player's writers, so that the first messages find their channels.
  const std::unique_ptr<view::View> live =
      start_live_view(a.view, a.options.domain, a.options.partition, "avs bag play", std::cerr);
  stop_on_interrupt();
  std::atomic<bool> paused{false};
  std::atomic<bool> done{false};
  RawTerminal terminal;
  std::thread keys;
  if (terminal.active()) {
    keys = std::thread([&] {
      while (!done) {
        pollfd p{STDIN_FILENO, POLLIN, 0};
        if (poll(&p, 1, 100) <= 0) continue;
        char c = 0;
        if (read(STDIN_FILENO, &c, 1) != 1) continue;
        if (c == ' ') paused = !paused;
        if (c == 'q') request_stop();
      }
    });
  }
  const bool tty = isatty(STDERR_FILENO) != 0;
  bag::PlayControl control;
  control.stop = &stop_requested();
  control.paused = &paused;
  if (tty) {
    control.on_progress = [](const bag::PlayProgress& p) {
      const double f = p.duration_s > 0 ? std::min(1.0, p.bag_time_s / p.duration_s) : 1.0;
      const int width = 30;
      const int filled = static_cast<int>(f * width);
      std::string bar(static_cast<std::size_t>(filled), '#');
      bar.resize(width, '-');
      std::fprintf(stderr, "\r\033[K[%s] %6.2f / %.2f s  %llu msgs%s%s", bar.c_str(), p.bag_time_s,
                   p.duration_s, static_cast<unsigned long long>(p.published),
                   p.pass > 0 ? (" pass " + std::to_string(p.pass + 1)).c_str() : "",
                   p.paused ? "  PAUSED (space: resume)" : "  (space: pause, q: quit)");
    };
  }
  int status = 0;
  try {
    const bag::PlayResult r = bag::play(a.options, control);
    if (tty) std::fprintf(stderr, "\r\033[K");
    std::printf("published %llu messages\n", static_cast<unsigned long long>(r.published));
    for (const auto& [topic, n] : r.per_topic) {
      std::printf("  %-32s %llu\n", topic.c_str(), static_cast<unsigned long long>(n));
    }
    if (!r.skipped_chunks.empty()) {
      std::printf("skipped %zu corrupt chunk(s) (`avs bag repair -o` keeps the rest)\n",
                  r.skipped_chunks.size());
    }
    if (r.gaps_shortened > 0) {
      std::printf("shortened %llu gap(s) above --max-gap %g s\n",
                  static_cast<unsigned long long>(r.gaps_shortened), a.options.max_gap_s);
    }
    if (!r.skipped.empty() || !r.skipped_chunks.empty()) status = 3;
  } catch (const std::exception& e) {
    if (tty) std::fprintf(stderr, "\r\033[K");
    std::cerr << e.what() << "\n";
    status = 1;
  }
  done = true;
  if (keys.joinable()) keys.join();
  if (live) live->stop();
  return status;
}

// ---- info / repair ------------------------------------------------------------------------

int run_info(const std::string& file) {
  mcap::BagInfo info;
  if (mcap::Status s = mcap::read_bag_info(file, info); !s.ok()) {
    std::cerr << "avs bag info: " << file << ": " << s.to_string() << "\n";
    return 1;
  }
  std::cout << mcap::format_bag_info(info);
  return 0;
}

int run_repair(const std::string& file, std::string output) {
  if (output.empty()) output = file;
  mcap::RepairReport report;
  const mcap::Status s = mcap::repair_file(file, output, report);
  if (!s.ok() && report.written_to.empty()) {
    std::cerr << "avs bag repair: " << file << ": " << s.to_string() << "\n";
    return 1;
  }
  std::cout << "repaired " << file << " -> " << report.written_to.string() << ": kept "
            << report.chunks_kept << " chunks, " << report.messages_kept << " messages";
  if (report.bytes_dropped > 0)
    std::cout << "; dropped the last " << report.bytes_dropped << " bytes";
  std::cout << "\n";
  for (const auto& chunk : report.skipped_chunks) {
    std::cout << "  left out the corrupt chunk at offset " << chunk.offset << ": " << chunk.problem
              << "\n";
  }
  if (report.chunk_lengths_corrected > 0) {
    std::cout << "  corrected the length field of " << report.chunk_lengths_corrected
              << " chunk(s) (kept, framed by their own fields)\n";
  }
  if (!report.stopped_because.empty())
    std::cout << "  scan stopped: " << report.stopped_because << "\n";
  if (report.input_had_summary) {
    std::cout << "  (the input had a valid summary counting " << report.input_summary_messages
              << " messages)\n";
  }
  if (!s.ok()) std::cerr << "avs bag repair: " << s.to_string() << "\n";
  return s.ok() && report.skipped_chunks.empty() ? 0 : 3;
}

void add_bag_command(Command& app) {
  auto* bag = app.add_subcommand(
      "bag", "Record topics to MCAP files, play them back, inspect and repair them");
  bag->require_subcommand(1);

  static RecordArgs rec;
  auto* record = bag->add_subcommand(
      "record", "Record topics (serialised CDR as received) to an MCAP file; Ctrl-C stops cleanly");
  record->add_flag("-a,--all", rec.options.all,
                   "record every topic, including ones that appear later");
  record->add_option("topics", rec.options.topics, "topics to record (/name, name or rt/name)");
  record->add_option("-e,--regex", rec.options.include_regex,
                     "record topics whose name matches REGEX");
  record->add_option("-x,--exclude", rec.options.exclude_regex,
                     "never record topics whose name matches REGEX");
  record->add_option("-o,--output", rec.options.output, "MCAP file to write")->required();
  record->add_option("--compression", rec.compression, "chunk compression: zstd, lz4 or none")
      ->capture_default_str();
  record->add_option("--compression-level", rec.options.compression_level,
                     "zstd level (-7 to 22) / lz4 level (0 to 12; higher: lz4's HC mode)")
      ->capture_default_str()
      ->check_range(-7, 22);
  record->add_option("--chunk-size", rec.options.chunk_size_bytes, "uncompressed chunk size, bytes")
      ->capture_default_str()
      ->check_range(1024, 1 << 30);
  record->add_option("--max-size", rec.options.max_size_bytes,
                     "start a new file (<stem>_1.mcap, ...) when one reaches BYTES (0: never)")
      ->check_range(0, 1e15);
  record
      ->add_option("--max-duration", rec.options.max_duration_s,
                   "start a new file when one covers S seconds (0: never)")
      ->check_range(0, 1e9);
  record
      ->add_option("--queue-size", rec.queue_mb,
                   "MB of samples waiting for the writer before samples are dropped (and counted)")
      ->capture_default_str()
      ->check_range(0, 1e6);
  record
      ->add_option("--flush-interval", rec.options.flush_interval_s,
                   "close the open chunk at least this often, s (bounds what a kill loses)")
      ->capture_default_str()
      ->check_range(0.001, 3600);
  record->add_option("--duration", rec.duration_s, "stop after S seconds (0: until Ctrl-C/SIGTERM)")
      ->check_range(0, 1e9);
  rec.options.partition = environment_partition();
  add_domain_option(record, rec.options.domain);
  record->footer(
      "Exit status: 0 all received samples written; 3 some were lost (listed); 1 error.");
  record->callback([] { exit_status() = run_record(rec); });

  static PlayArgs pl;
  auto* play = bag->add_subcommand(
      "play", "Republish a recording with its timing and QoS (space: pause/resume)");
  play->add_option("file", pl.options.file, "MCAP file")->required();
  play->add_option("-r,--rate", pl.options.rate, "playback speed factor")
      ->capture_default_str()
      ->check_range(1e-3, 1e3);
  play->add_flag("-l,--loop", pl.options.loop, "start again at the end");
  play->add_option("--start-offset", pl.options.start_offset_s,
                   "skip the first S seconds of the bag")
      ->check_range(0, 1e9);
  play->add_option("--topics", pl.options.topics, "play only these topics");
  play->add_option("--remap", pl.remaps, "publish topic FROM as TO (FROM:=TO), repeatable");
  play->add_flag(
      "--clock", pl.options.clock,
      "publish /clock (rosgraph_msgs/msg/Clock) from the bag's log time, so a sim-time graph "
      "follows the recording");
  play->add_option("--clock-period", pl.options.clock_period_s,
                   "with --clock: publish /clock at least every S seconds of bag time")
      ->capture_default_str()
      ->check_range(1e-6, 3600);
  play->add_option("--delay", pl.options.delay_s,
                   "wait S seconds after creating the writers (discovery)")
      ->capture_default_str()
      ->check_range(0, 3600);
  play->add_option("--max-gap", pl.options.max_gap_s,
                   "wait at most S seconds of bag time between two messages (a longer gap, "
                   "e.g. a corrupt log_time, is shortened and said)")
      ->capture_default_str()
      ->check_range(1e-3, 1e6);
  pl.options.partition = environment_partition();
  add_domain_option(play, pl.options.domain);
  add_live_view_options(play, pl.view, "the playback");
  play->callback([] { exit_status() = run_play(pl); });

  static std::string info_file;
  auto* info = bag->add_subcommand(
      "info", "Duration, start/end, size, compression, per topic type/count/rate");
  info->add_option("file", info_file, "MCAP file")->required();
  info->callback([] { exit_status() = run_info(info_file); });

  static std::string repair_file, repair_output;
  auto* repair = bag->add_subcommand(
      "repair", "Rewrite the index and summary of a file cut short (e.g. a killed recorder)");
  repair->add_option("file", repair_file, "MCAP file")->required();
  repair->add_option("-o,--output", repair_output,
                     "write here instead of replacing FILE (FILE is replaced only when nothing "
                     "is lost; otherwise the result goes to FILE.repaired.mcap)");
  repair->footer(
      "Exit status: 0 repaired; 3 repaired with corrupt parts left out (FILE kept as it was when "
      "repairing in place); 1 error.");
  repair->callback([] { exit_status() = run_repair(repair_file, repair_output); });
}

}  // namespace

AVS_REGISTER_COMMAND(add_bag_command)

}  // namespace avs::cli
