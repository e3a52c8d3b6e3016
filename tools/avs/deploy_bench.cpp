// avs bench transport: one-way latency of 256 KiB images at 1 kHz between two processes, over
// UDP on loopback (the Cyclone configuration a deployment generates, on `lo`) and through
// iceoryx shared memory (the same plus `shared_memory: true`, RouDi started by the bench).
// Method as in ../shared/reference/dds-cyclone-notes.md: the publisher waits for the reader,
// writes on an absolute 1 ms schedule and stamps CLOCK_MONOTONIC just before dds_write; the
// subscriber takes with a waitset and subtracts the stamp (one host, one clock).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <iostream>
#include <sstream>
#include <thread>

#include "avs/bench/report.hpp"
#include "avs/deploy/deployment.hpp"
#include "avs/deploy/roudi.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/error.hpp"
#include "commands.hpp"
#include "dds/ddsc/dds_loan_api.h"  // dds_is_shared_memory_available (not in dds.h in 0.10)
#include "dds_environment.hpp"
#include "sensor_msgs.h"

extern char** environ;

namespace avs::cli {
namespace {

using Image = sensor_msgs_msg_dds__Image_;
constexpr const char* kTopic = "rt/avs_bench/transport_image";

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

struct PeerOptions {
  std::string role;
  int count = 5000;
  double rate_hz = 1000;
  int bytes = 262144;
  int domain = 179;
};

runtime::QosProfile bench_qos() {
  runtime::QosProfile q;  // reliable, volatile; deeper than the default 4 of the notes
  q.depth = 16;
  return q;
}

/// The subscriber: prints "received=N p50_us=.. p90_us=.. p99_us=.. max_us=.." on stdout.
int run_sub(const PeerOptions& o) {
  runtime::dds::Participant participant(static_cast<dds_domainid_t>(o.domain));
  runtime::dds::Topic topic(participant, &sensor_msgs_msg_dds__Image__desc, kTopic, bench_qos());
  runtime::Qos qos(bench_qos());
  runtime::dds::Entity reader(runtime::check_dds(
      dds_create_reader(participant.get(), topic.get(), qos.get(), nullptr), "bench reader"));
  runtime::dds::Entity waitset(
      runtime::check_dds(dds_create_waitset(participant.get()), "waitset"));
  runtime::dds::Entity cond(
      runtime::check_dds(dds_create_readcondition(reader.get(), DDS_ANY_STATE), "read condition"));
  runtime::check_dds(dds_waitset_attach(waitset.get(), cond.get(), 0), "attach");
  std::cout << "ready" << std::endl;
  std::vector<double> latency_us;
  latency_us.reserve(static_cast<std::size_t>(o.count));
  const std::int64_t give_up =
      mono_ns() + static_cast<std::int64_t>((o.count / o.rate_hz + 20.0) * 1e9);
  std::int64_t last_sample = 0;
  while (static_cast<int>(latency_us.size()) < o.count && mono_ns() < give_up) {
    // After the stream started, 2 s without a sample means the publisher is done.
    if (last_sample > 0 && mono_ns() - last_sample > 2'000'000'000) break;
    dds_waitset_wait(waitset.get(), nullptr, 0, DDS_MSECS(100));
    void* samples[16] = {};
    dds_sample_info_t infos[16];
    const int n = dds_take(reader.get(), samples, infos, 16, 16);
    const std::int64_t now = mono_ns();
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* img = static_cast<const Image*>(samples[i]);
      const std::int64_t stamp = static_cast<std::int64_t>(img->header.stamp.sec) * 1'000'000'000 +
                                 img->header.stamp.nanosec;
      latency_us.push_back(static_cast<double>(now - stamp) / 1000.0);
      last_sample = now;
    }
    if (n > 0) dds_return_loan(reader.get(), samples, n);
  }
  std::sort(latency_us.begin(), latency_us.end());
  auto pct = [&](double p) {
    if (latency_us.empty()) return 0.0;
    return latency_us[std::min(
        latency_us.size() - 1,
        static_cast<std::size_t>(p * static_cast<double>(latency_us.size())))];
  };
  std::cout << "received=" << latency_us.size() << " p50_us=" << pct(0.5) << " p90_us=" << pct(0.9)
            << " p99_us=" << pct(0.99) << " max_us=" << (latency_us.empty() ? 0 : latency_us.back())
            << std::endl;
  return 0;
}

/// The publisher: prints "sent=N shm=0|1" on stdout.
int run_pub(const PeerOptions& o) {
  runtime::dds::Participant participant(static_cast<dds_domainid_t>(o.domain));
  runtime::dds::Topic topic(participant, &sensor_msgs_msg_dds__Image__desc, kTopic, bench_qos());
  runtime::Qos qos(bench_qos());
  runtime::dds::Entity writer(runtime::check_dds(
      dds_create_writer(participant.get(), topic.get(), qos.get(), nullptr), "bench writer"));
  const std::int64_t match_deadline = mono_ns() + 15'000'000'000;
  for (;;) {
    dds_publication_matched_status_t st{};
    dds_get_publication_matched_status(writer.get(), &st);
    if (st.current_count > 0) break;
    if (mono_ns() > match_deadline) {
      std::cerr << "avs bench transport: no subscriber matched within 15 s\n";
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(o.bytes), 0x5a);
  Image img{};
  img.height = 512;
  img.width = static_cast<std::uint32_t>(o.bytes / 512);
  img.step = img.width;
  img.encoding = const_cast<char*>("mono8");
  img.header.frame_id = const_cast<char*>("camera");
  img.data._buffer = pixels.data();
  img.data._length = img.data._maximum = static_cast<std::uint32_t>(pixels.size());
  img.data._release = false;
  const auto period = static_cast<std::int64_t>(1e9 / o.rate_hz);
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  int sent = 0;
  for (int i = 0; i < o.count; ++i) {
    next.tv_nsec += period;
    while (next.tv_nsec >= 1'000'000'000) {
      next.tv_nsec -= 1'000'000'000;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    const std::int64_t now = mono_ns();
    img.header.stamp.sec = static_cast<std::int32_t>(now / 1'000'000'000);
    img.header.stamp.nanosec = static_cast<std::uint32_t>(now % 1'000'000'000);
    if (dds_write(writer.get(), &img) >= 0) ++sent;
  }
  std::cout << "sent=" << sent << " shm=" << (dds_is_shared_memory_available(writer.get()) ? 1 : 0)
            << std::endl;
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let reliable repairs finish
  return 0;
}

/// A child `avs transport-peer ROLE ...` with CYCLONEDDS_URI = xml; its stdout on a pipe.
struct Peer {
  pid_t pid = -1;
  FILE* out = nullptr;
  Peer(const PeerOptions& o, const std::string& xml) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    std::vector<std::string> args = {"avs",
                                     "transport-peer",
                                     o.role,
                                     "--count",
                                     std::to_string(o.count),
                                     "--rate",
                                     std::to_string(o.rate_hz),
                                     "--bytes",
                                     std::to_string(o.bytes),
                                     "--domain",
                                     std::to_string(o.domain)};
    std::vector<std::string> env;
    for (char** e = environ; *e != nullptr; ++e) {
      if (std::strncmp(*e, "CYCLONEDDS_URI=", 15) != 0 &&
          std::strncmp(*e, "AVS_PARTITION=", 14) != 0) {
        env.emplace_back(*e);
      }
    }
    env.push_back("CYCLONEDDS_URI=" + xml);
    std::vector<char*> argv, envp;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    for (auto& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);
    pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
      dup2(fds[1], 1);
      close(fds[0]);
      close(fds[1]);
      execve("/proc/self/exe", argv.data(), envp.data());
      _exit(127);
    }
    close(fds[1]);
    out = fdopen(fds[0], "r");
  }
  std::string line() {
    char buf[512];
    return fgets(buf, sizeof buf, out) != nullptr ? std::string(buf) : std::string();
  }
  ~Peer() {
    if (out != nullptr) fclose(out);
    if (pid > 0) {
      kill(pid, SIGTERM);
      waitpid(pid, nullptr, 0);
    }
  }
};

double field(const std::string& line, const std::string& key) {
  const auto pos = line.find(key + "=");
  return pos == std::string::npos ? -1 : std::atof(line.c_str() + pos + key.size() + 1);
}

struct RunResult {
  double received = 0, p50 = 0, p90 = 0, p99 = 0, max = 0, shm = 0;
  std::string error;
};

RunResult run_pair(PeerOptions o, const std::string& xml) {
  RunResult r;
  o.role = "sub";
  Peer sub(o, xml);
  if (sub.line().rfind("ready", 0) != 0) {
    r.error = "subscriber did not start";
    return r;
  }
  o.role = "pub";
  Peer pub(o, xml);
  const std::string sent = pub.line();
  const std::string got = sub.line();
  if (got.empty() || sent.empty()) {
    r.error = "no result (publisher: '" + sent + "', subscriber: '" + got + "')";
    return r;
  }
  r = {field(got, "received"),
       field(got, "p50_us"),
       field(got, "p90_us"),
       field(got, "p99_us"),
       field(got, "max_us"),
       field(sent, "shm"),
       ""};
  return r;
}

bench::Report transport_bench(const std::vector<std::string>& args) {
  PeerOptions o;
  o.count = 5000;
  bench::Options given("transport", args);
  o.count = static_cast<int>(given.integer("--count", o.count, 1, 10000000));
  o.rate_hz = given.number("--rate", o.rate_hz, 1.0, 100000.0);
  o.bytes = static_cast<int>(given.integer("--bytes", o.bytes, 16, 64 << 20));
  given.finish();
  o.domain = domain_or_environment(179);
  // One local host, on lo, as a deployment would configure it.
  deploy::Deployment d;
  d.hosts.push_back(deploy::Host{"local", "", "lo", {}, {}});
  d.transport.image_bytes = static_cast<std::uint64_t>(o.bytes);
  d.transport.image_rate_hz = o.rate_hz;
  const std::string udp_xml = deploy::cyclone_config(d, d.hosts[0], "bench");
  d.shared_memory.enabled = true;
  const std::string shm_xml = deploy::cyclone_config(d, d.hosts[0], "bench");

  bench::Report report;
  std::ostringstream title;
  title << "avs bench transport: " << o.bytes << " B images at " << o.rate_hz << " Hz, " << o.count
        << " samples, one-way latency between two processes (reliable, keep last 16)";
  report.title = title.str();
  const RunResult udp = run_pair(o, udp_xml);
  if (!udp.error.empty()) throw std::runtime_error("UDP run: " + udp.error);
  RunResult shm;
  try {
    deploy::Roudi roudi;
    shm = run_pair(o, shm_xml);
    report.notes.push_back("shared memory through " + roudi.description());
  } catch (const std::exception& e) {
    shm.error = e.what();
  }
  const std::string peer = "UDP loopback (deployment config, lo)";
  if (shm.error.empty()) {
    report.rows.push_back(
        {"image latency p50, iceoryx shared memory", "us", shm.p50, peer, udp.p50});
    report.rows.push_back(
        {"image latency p90, iceoryx shared memory", "us", shm.p90, peer, udp.p90});
    report.rows.push_back(
        {"image latency p99, iceoryx shared memory", "us", shm.p99, peer, udp.p99});
    report.rows.push_back(
        {"image latency max, iceoryx shared memory", "us", shm.max, peer, udp.max});
    report.rows.push_back({"images received, shared memory", "", shm.received, peer, udp.received});
    report.json["shm_p50_us"] = shm.p50;
    report.json["shm_p99_us"] = shm.p99;
    report.json["shm_received"] = shm.received;
    report.json["shm_writer_uses_shared_memory"] = shm.shm;
    if (shm.shm < 1) {
      report.notes.push_back(
          "warning: the shared-memory writer reports shared memory NOT available "
          "(dds_is_shared_memory_available = 0): that run went over UDP");
    }
  } else {
    report.rows.push_back({"image latency p50, UDP loopback", "us", udp.p50, "", 0});
    report.rows.push_back({"image latency p99, UDP loopback", "us", udp.p99, "", 0});
    report.notes.push_back("shared memory not measured: " + shm.error);
  }
  report.json["udp_p50_us"] = udp.p50;
  report.json["udp_p90_us"] = udp.p90;
  report.json["udp_p99_us"] = udp.p99;
  report.json["udp_received"] = udp.received;
  report.json["count"] = o.count;
  report.json["image_bytes"] = o.bytes;
  report.notes.push_back("ratio = UDP / shared memory (above 1: shared memory is faster)");
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    char load[64] = {};
    if (std::fgets(load, sizeof load, f) != nullptr) {
      report.notes.push_back(std::string("load average after the run (/proc/loadavg): ") + load);
    }
    std::fclose(f);
  }
  return report;
}

AVS_REGISTER_BENCH(transport, "transport",
                   "image latency between two processes: iceoryx shared memory vs UDP loopback",
                   transport_bench);

void add_transport_peer_command(Command& app) {
  auto* cmd = app.add_subcommand("transport-peer", "internal: one side of avs bench transport");
  cmd->group("");  // hidden from avs --help
  static PeerOptions o;
  cmd->add_option("role", o.role, "pub or sub")->required()->check_member({"pub", "sub"});
  cmd->add_option("--count", o.count, "samples")->capture_default_str();
  cmd->add_option("--rate", o.rate_hz, "Hz")->capture_default_str();
  cmd->add_option("--bytes", o.bytes, "image bytes")->capture_default_str();
  add_domain_option(cmd, o.domain);
  cmd->callback([] {
    try {
      exit_status() = o.role == "pub" ? run_pub(o) : run_sub(o);
    } catch (const std::exception& e) {
      std::cerr << "avs transport-peer: " << e.what() << "\n";
      exit_status() = 1;
    }
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_transport_peer_command)

}  // namespace avs::cli
