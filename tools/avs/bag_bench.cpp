// avs bench bag: records a 512x512 mono8 pattern-frame topic at 1000 fps (262 MB/s raw) plus
// small topics, published by a second process, with each chunk compression; reports
// throughput, file size and every lost message (sent - written, and what the recorder saw).
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "avs/bag/recorder.hpp"
#include "avs/bench/report.hpp"
#include "avs/mcap/info.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/error.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs_msgs.h"
#include "dds_environment.hpp"

extern char** environ;

namespace avs::cli {

namespace {

struct BenchArgs {
  double duration_s = 10;
  double fps = 1000;
  int width = 512;
  int height = 512;
  std::string role;  // "publisher" in the child
  std::string dir;
  std::vector<std::string> compressions{"none", "lz4", "zstd"};
  bool keep = false;
  int domain = -1;
  int history = 0;  // publisher KEEP_LAST depth; 0 = KEEP_ALL
};

/// Options as `--key=value` (`avs bench` hands unknown options and positional words over
/// separately, so `--key value` may arrive out of order) or `--key value`.
BenchArgs parse_args(const std::vector<std::string>& raw) {
  BenchArgs a;
  bench::Options given("bag", raw, {"--keep", "--help", "-h"});
  if (given.flag("--help") || given.flag("-h")) {
    std::printf(
        "avs bench bag [--duration=S] [--fps=N] [--size=PX] [--compression=none,lz4,zstd]\n"
        "              [--dir=DIR] [--keep] [--domain=ID] [--publisher-history=N]\n"
        "Records /bench_bag/pattern_frames (avs_msgs/msg/PatternFrame, PXxPX mono8, N fps) with\n"
        "/bench_bag/target (1 kHz), /bench_bag/torque (1 kHz) and /bench_bag/match (100 Hz) from "
        "a\n"
        "publisher process for S seconds per compression; files go to DIR (default $TMPDIR or "
        "/tmp)\n"
        "and are deleted unless --keep. The publisher is reliable KEEP_ALL, or KEEP_LAST N with\n"
        "--publisher-history=N (to show the losses a reader is not told about).\n"
        "  --domain=ID  DDS domain id (default: $AVS_DOMAIN_ID or 0)\n");
    std::exit(0);
  }
  a.duration_s = given.number("--duration", a.duration_s, 0.1, 3600.0);
  a.fps = given.number("--fps", a.fps, 1.0, 10000.0);
  a.width = a.height = static_cast<int>(given.integer("--size", a.width, 8, 4096));
  a.role = given.text("--role", a.role);
  a.dir = given.text("--dir", a.dir);
  a.history = static_cast<int>(given.integer("--publisher-history", a.history, 0, 1000000));
  a.keep = given.flag("--keep");
  a.domain = static_cast<int>(given.integer("--domain", a.domain, 0, 232));
  if (const std::string list = given.text("--compression", ""); !list.empty()) {
    a.compressions.clear();
    std::stringstream ss(list);
    for (std::string c; std::getline(ss, c, ',');) a.compressions.push_back(c);
  }
  given.finish();
  if (a.domain < 0) a.domain = domain_or_environment(0);
  return a;
}

// ---- publisher (child process) -------------------------------------------------------------

void sleep_until(const timespec& t) {
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, nullptr) == EINTR) {
  }
}

timespec add_ns(timespec t, std::int64_t ns) {
  t.tv_nsec += ns;
  while (t.tv_nsec >= 1'000'000'000) {
    t.tv_nsec -= 1'000'000'000;
    ++t.tv_sec;
  }
  return t;
}

void stamp(std_msgs_msg_dds__Header_& h, const char* frame) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  h.stamp.sec = static_cast<std::int32_t>(ns / 1'000'000'000);
  h.stamp.nanosec = static_cast<std::uint32_t>(ns % 1'000'000'000);
  h.frame_id = const_cast<char*>(frame);
}

/// A data writer with explicit QoS (keep all), as the bench's publisher needs.
class BenchWriter {
 public:
  BenchWriter(const runtime::dds::Participant& p, const runtime::dds::Topic& t,
              const runtime::dds::EndpointQos& q)
      : entity_(runtime::check_dds(dds_create_writer(p.get(), t.get(), q.to_dds().get(), nullptr),
                                   "create writer on " + t.name())),
        name_(t.name()) {}
  void write(const void* sample) {
    runtime::check_dds(dds_write(entity_.get(), sample), "write " + name_);
  }
  std::uint32_t matched_readers() const {
    dds_publication_matched_status_t s{};
    runtime::check_dds(dds_get_publication_matched_status(entity_.get(), &s), "matched " + name_);
    return s.current_count;
  }
  dds_entity_t get() const { return entity_.get(); }

 private:
  runtime::dds::Entity entity_;
  std::string name_;
};

/// Publishes for `duration_s`, then prints "sent <topic> <count>" lines and exits.
[[noreturn]] void run_publisher(const BenchArgs& a) {
  runtime::dds::Participant participant(a.domain);
  // Reliable, KEEP_ALL: when the recorder acknowledges late the writer waits (Cyclone's writer
  // history cache, WhcHigh 8 MB in avs's default config) instead of dropping. A reliable
  // KEEP_LAST writer drops unacknowledged samples from its history when it runs ahead, and
  // Cyclone 0.10's reader is not told (no SAMPLE_LOST): docs/bag.md, loss accounting.
  runtime::dds::EndpointQos qos;
  qos.keep_all = a.history <= 0;
  qos.depth = a.history;
  const runtime::QosProfile topic_qos;
  runtime::dds::Topic frames_t(participant, &avs_msgs_msg_dds__PatternFrame__desc,
                               "rt/bench_bag/pattern_frames", topic_qos);
  runtime::dds::Topic target_t(participant, &avs_msgs_msg_dds__TargetObservation__desc,
                               "rt/bench_bag/target", topic_qos);
  runtime::dds::Topic torque_t(participant, &avs_msgs_msg_dds__JointTorqueCommand__desc,
                               "rt/bench_bag/torque", topic_qos);
  runtime::dds::Topic match_t(participant, &avs_msgs_msg_dds__MatchResult__desc,
                              "rt/bench_bag/match", topic_qos);
  BenchWriter frames(participant, frames_t, qos);
  BenchWriter target(participant, target_t, qos);
  BenchWriter torque(participant, torque_t, qos);
  BenchWriter match(participant, match_t, qos);

  // Pattern-like frames: vertical Gray-code stripes of 9 bits, positive and negative, with
  // 3-bit noise (what a camera sees of the projected patterns).
  const std::size_t pixels = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  std::vector<std::vector<std::uint8_t>> images(18, std::vector<std::uint8_t>(pixels));
  std::mt19937 rng(7);
  for (int k = 0; k < 18; ++k) {
    const int bit = k / 2;
    for (int y = 0; y < a.height; ++y) {
      for (int x = 0; x < a.width; ++x) {
        const unsigned code = static_cast<unsigned>(x * 512 / a.width);
        const unsigned gray = code ^ (code >> 1);
        bool on = ((gray >> (8 - bit)) & 1u) != 0;
        if (k % 2 == 1) on = !on;
        images[static_cast<std::size_t>(k)]
              [static_cast<std::size_t>(y) * static_cast<std::size_t>(a.width) +
               static_cast<std::size_t>(x)] =
                  static_cast<std::uint8_t>((on ? 200 : 30) + (rng() & 7u));
      }
    }
  }

  // Wait until the recorder reads every topic, then give discovery a moment more.
  const auto wait_end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (frames.matched_readers() == 0 || target.matched_readers() == 0 ||
         torque.matched_readers() == 0 || match.matched_readers() == 0) {
    if (std::chrono::steady_clock::now() > wait_end) {
      std::fprintf(stderr, "bench bag publisher: no recorder matched within 30 s\n");
      std::exit(1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  char encoding[] = "mono8";
  char joint_a[] = "pan";
  char joint_b[] = "tilt";
  char* joint_names[] = {joint_a, joint_b};
  double torques[2] = {0.1, -0.2};
  char camera[] = "camera";
  std::uint64_t n_frames = 0, n_target = 0, n_torque = 0, n_match = 0, late = 0;
  const auto period_ns = static_cast<std::int64_t>(1e9 / a.fps);
  const auto total = static_cast<std::uint64_t>(a.duration_s * a.fps);
  timespec next;
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (std::uint64_t i = 0; i < total; ++i) {
    next = add_ns(next, period_ns);
    avs_msgs_msg_dds__PatternFrame_ f{};
    stamp(f.header, camera);
    f.image.header = f.header;
    f.image.height = static_cast<std::uint32_t>(a.height);
    f.image.width = static_cast<std::uint32_t>(a.width);
    f.image.encoding = encoding;
    f.image.step = static_cast<std::uint32_t>(a.width);
    auto& img = images[i % images.size()];
    f.image.data._buffer = img.data();
    f.image.data._length = f.image.data._maximum = static_cast<std::uint32_t>(img.size());
    f.bit_index = static_cast<std::uint8_t>((i % 18) / 2);
    f.bit_count = 9;
    f.positive = (i % 2) == 0;
    f.cycle = static_cast<std::uint32_t>(i / 18);
    frames.write(&f);
    ++n_frames;
    avs_msgs_msg_dds__TargetObservation_ t{};
    stamp(t.header, camera);
    t.m00 = static_cast<double>(i);
    t.valid = true;
    target.write(&t);
    ++n_target;
    avs_msgs_msg_dds__JointTorqueCommand_ c{};
    stamp(c.header, camera);
    c.name._buffer = joint_names;
    c.name._length = c.name._maximum = 2;
    c.torque_nm._buffer = torques;
    c.torque_nm._length = c.torque_nm._maximum = 2;
    torque.write(&c);
    ++n_torque;
    if (i % 10 == 0) {
      avs_msgs_msg_dds__MatchResult_ m{};
      stamp(m.header, camera);
      m.pose.orientation.w = 1;
      m.iterations = static_cast<std::uint32_t>(i);
      match.write(&m);
      ++n_match;
    }
    timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    if (now.tv_sec > next.tv_sec || (now.tv_sec == next.tv_sec && now.tv_nsec > next.tv_nsec)) {
      ++late;
    } else {
      sleep_until(next);
    }
  }
  // Let reliable delivery finish before the writers go away.
  dds_wait_for_acks(frames.get(), DDS_SECS(10));
  dds_wait_for_acks(target.get(), DDS_SECS(10));
  dds_wait_for_acks(torque.get(), DDS_SECS(10));
  dds_wait_for_acks(match.get(), DDS_SECS(10));
  std::printf(
      "sent /bench_bag/pattern_frames %llu\nsent /bench_bag/target %llu\n"
      "sent /bench_bag/torque %llu\nsent /bench_bag/match %llu\nlate %llu\n",
      static_cast<unsigned long long>(n_frames), static_cast<unsigned long long>(n_target),
      static_cast<unsigned long long>(n_torque), static_cast<unsigned long long>(n_match),
      static_cast<unsigned long long>(late));
  std::fflush(stdout);
  std::_Exit(0);
}

// ---- recorder (parent) ---------------------------------------------------------------------

struct Run {
  std::string compression;
  std::map<std::string, std::uint64_t> sent;
  std::uint64_t late = 0;
  bag::RecorderStatus status;
  double seconds = 0;  // first to last received sample (publishing time)
  std::uint64_t file_bytes = 0;
  double ratio = 0;
};

Run run_one(const BenchArgs& a, const std::string& compression, const std::filesystem::path& file) {
  Run run;
  run.compression = compression;
  bag::RecordOptions o;
  o.include_regex = "^/bench_bag/";
  o.output = file;
  o.compression = *mcap::parse_compression(compression);
  o.domain = a.domain;
  o.queue_bytes = 2ull << 30;
  bag::Recorder recorder(o);
  recorder.start();

  int out[2];
  if (pipe(out) != 0) throw runtime::Error("avs bench bag: pipe failed");
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::vector<std::string> words = {self,
                                    "bench",
                                    "bag",
                                    "--role=publisher",
                                    "--duration=" + std::to_string(a.duration_s),
                                    "--fps=" + std::to_string(a.fps),
                                    "--size=" + std::to_string(a.width),
                                    "--domain=" + std::to_string(a.domain),
                                    "--publisher-history=" + std::to_string(a.history)};
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  pid_t child = 0;
  const int rc = posix_spawn(&child, self.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  if (rc != 0)
    throw runtime::Error("avs bench bag: cannot start the publisher: " +
                         std::string(std::strerror(rc)));
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = read(out[0], buf, sizeof buf)) > 0;)
    text.append(buf, static_cast<std::size_t>(n));
  close(out[0]);
  int wstatus = 0;
  waitpid(child, &wstatus, 0);
  if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0) {
    throw runtime::Error("avs bench bag: the publisher process failed (status " +
                         std::to_string(wstatus) + ")");
  }
  std::istringstream lines(text);
  for (std::string word; lines >> word;) {
    if (word == "sent") {
      std::string topic;
      std::uint64_t n = 0;
      lines >> topic >> n;
      run.sent[topic] = n;
    } else if (word == "late") {
      lines >> run.late;
    }
  }
  // Everything sent has been acknowledged: what is not in the queue or file by now is lost.
  // Acknowledged samples may still sit in Cyclone's delivery queue on a loaded machine.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  recorder.stop();
  run.status = recorder.status();
  mcap::BagInfo info;
  if (mcap::Status s = mcap::read_bag_info(file, info); !s.ok()) {
    throw runtime::Error("avs bench bag: reading back " + file.string() + ": " + s.to_string());
  }
  run.seconds = info.duration_s;
  run.file_bytes = info.file_size_bytes;
  run.ratio = info.chunk_compressed_bytes > 0 ? static_cast<double>(info.chunk_uncompressed_bytes) /
                                                    static_cast<double>(info.chunk_compressed_bytes)
                                              : 0;
  if (!a.keep) std::filesystem::remove(file);
  return run;
}

bench::Report run_bench(const std::vector<std::string>& args) {
  const BenchArgs a = parse_args(args);
  if (a.role == "publisher") run_publisher(a);
  std::filesystem::path dir = a.dir;
  if (dir.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    dir = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
  }
  bench::Report report;
  char title[256];
  std::snprintf(
      title, sizeof title,
      "avs bag record: %dx%d mono8 pattern frames at %.0f fps (%.0f MB/s raw) + 3 small topics, "
      "%.0f s per compression, files in %s",
      a.width, a.height, a.fps, a.fps * a.width * a.height / 1e6, a.duration_s,
      dir.string().c_str());
  report.title = title;
  for (const auto& c : a.compressions) {
    if (!mcap::parse_compression(c))
      throw runtime::Error("avs bench bag: unknown compression " + c);
    const auto file = dir / ("avs_bench_bag_" + std::to_string(getpid()) + "_" + c + ".mcap");
    const Run r = run_one(a, c, file);
    std::uint64_t sent = 0, written = 0;
    for (const auto& [topic, n] : r.sent) sent += n;
    for (const auto& t : r.status.topics) written += t.written;
    const std::uint64_t missing = sent > written ? sent - written : 0;
    const double mb = static_cast<double>(r.status.bytes_received) / 1e6;
    const double rate = r.seconds > 0 ? mb / r.seconds : 0;
    report.rows.push_back({c + ": recorded throughput", "MB/s", rate, "", 0});
    report.rows.push_back(
        {c + ": file size", "MB", static_cast<double>(r.file_bytes) / 1e6, "", 0});
    report.rows.push_back(
        {c + ": messages lost (sent - written)", "", static_cast<double>(missing), "", 0});
    report.rows.push_back(
        {c + ": losses the recorder reported", "", static_cast<double>(r.status.lost), "", 0});
    report.json[c + "_throughput_MBps"] = rate;
    report.json[c + "_file_MB"] = static_cast<double>(r.file_bytes) / 1e6;
    report.json[c + "_compression_ratio"] = r.ratio;
    report.json[c + "_sent_count"] = static_cast<double>(sent);
    report.json[c + "_written_count"] = static_cast<double>(written);
    report.json[c + "_lost_count"] = static_cast<double>(missing);
    report.json[c + "_reported_lost_count"] = static_cast<double>(r.status.lost);
    report.json[c + "_queue_peak_MB"] = static_cast<double>(r.status.queue_bytes_peak) / 1e6;
    report.json[c + "_publisher_late_count"] = static_cast<double>(r.late);
    char note[512];
    std::snprintf(
        note, sizeof note,
        "%s: %llu sent, %llu written, %llu lost (%llu reported by the recorder), chunk "
        "compression %.2fx, queue peak %.0f MB, publisher late %llu of %llu frames",
        c.c_str(), static_cast<unsigned long long>(sent), static_cast<unsigned long long>(written),
        static_cast<unsigned long long>(missing), static_cast<unsigned long long>(r.status.lost),
        r.ratio, static_cast<double>(r.status.queue_bytes_peak) / 1e6,
        static_cast<unsigned long long>(r.late),
        static_cast<unsigned long long>(r.sent.count("/bench_bag/pattern_frames")
                                            ? r.sent.at("/bench_bag/pattern_frames")
                                            : 0));
    report.notes.push_back(note);
    for (const auto& t : r.status.topics) {
      const auto sent_it = r.sent.find(t.topic);
      const std::uint64_t topic_sent = sent_it == r.sent.end() ? 0 : sent_it->second;
      if (topic_sent != t.written || t.lost() > 0) {
        report.notes.push_back("  " + c + " " + t.topic + ": " + std::to_string(topic_sent) +
                               " sent, " + std::to_string(t.received) + " received, " +
                               std::to_string(t.written) + " written, " + std::to_string(t.lost()) +
                               " reported lost");
      }
    }
    if (missing > r.status.lost) {
      report.notes.push_back("WARNING " + c + ": " + std::to_string(missing - r.status.lost) +
                             " message(s) missing that the recorder did not report");
    }
  }
  report.notes.push_back(
      "No peer: rosbag2 is not installed on this machine; the publisher is a second process "
      "(reliable, " +
      (a.history > 0 ? "keep last " + std::to_string(a.history) : std::string("keep all")) + ").");
  return report;
}

}  // namespace

AVS_REGISTER_BENCH(
    bag, "bag", "MCAP recording of 1000 fps 512x512 frames + small topics: throughput, size, loss",
    run_bench);

}  // namespace avs::cli
