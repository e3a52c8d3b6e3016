// `avs bench servo`: the servo drive's Modbus TCP cycle on loopback at 1 kHz against the
// simulated amplifier (two axes, own-thread clock), beside a bare libmodbus 0x17 loop with the
// same registers and rate as the peer. Keys: modbus_rtt_us_p50/p99 (per axis exchange),
// cycle_jitter_us_p99 (wake-up lateness against the absolute schedule). `--sched-fifo N` runs
// every thread of the bench (client, the amplifier's I/O and stepping threads) at SCHED_FIFO
// priority N, as a container's `realtime:` setting would; the report says which policy was in
// force, whichever way it was set (`chrt` works too).
#include <sched.h>
#include <time.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "avs/bench/report.hpp"
#include "avs/runtime/realtime.hpp"
#include "avs/servo/amplifier_server.hpp"
#include "avs/servo/drive_client.hpp"

namespace avs::servo {
namespace {

struct LoopFigures {
  double rtt_us_p50 = 0;
  double rtt_us_p99 = 0;
  double jitter_us_p50 = 0;
  double jitter_us_p99 = 0;
  std::uint64_t overruns = 0;
  std::uint64_t faults = 0;        ///< cycles with a link fault (reconnect back-off included)
  std::uint64_t fault_events = 0;  ///< link faults: healthy or missed cycle -> link fault
  std::uint64_t exchanges = 0;
  std::uint64_t missed_cycles = 0;
  std::uint64_t late_replies = 0;
};

double now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + ts.tv_nsec * 1e-9;
}

void sleep_until_s(double t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(std::floor(t));
  ts.tv_nsec = static_cast<long>((t - std::floor(t)) * 1e9);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// Runs `cycle_fn` every period for `seconds`, measuring the wake-up lateness.
template <typename Fn>
void run_periodic(double rate_hz, double seconds, SampleWindow& jitter_us, LoopFigures& fig,
                  Fn&& cycle_fn) {
  const double period = 1.0 / rate_hz;
  const auto cycles = static_cast<long>(seconds * rate_hz);
  double next = now_s() + period;
  for (long k = 0; k < cycles; ++k) {
    sleep_until_s(next);
    const double woke = now_s();
    jitter_us.add((woke - next) * 1e6);
    cycle_fn(woke);
    next += period;
    if (now_s() > next) {
      ++fig.overruns;
      while (now_s() > next) next += period;  // skip missed slots, keep the schedule
    }
  }
}

LoopFigures run_ours(int port, double rate_hz, double seconds) {
  DriveClientConfig config = default_drive_client_config("127.0.0.1", port);
  config.cycle_rate_hz = rate_hz;
  config.response_timeout_s = 0.4 / rate_hz;
  config.command_freshness.timeout_s = 0.05;
  DriveClient client(config);
  client.connect();
  client.activate(now_s());
  LoopFigures fig;
  SampleWindow jitter(1 << 20);
  CycleResult result;
  bool faulted = false;
  run_periodic(rate_hz, seconds, jitter, fig, [&](double t) {
    client.set_command({0.05 * std::sin(2 * M_PI * t), 0.01 * std::sin(2 * M_PI * t)}, t, t);
    client.cycle(t, result);
    if (result.link_fault) ++fig.faults;
    if (result.link_fault && !faulted) ++fig.fault_events;
    faulted = result.link_fault;
  });
  const LinkStatistics stats = client.statistics();
  fig.exchanges = stats.exchanges;
  fig.missed_cycles = stats.missed_cycles;
  fig.late_replies = stats.late_replies;
  fig.rtt_us_p50 = stats.rtt_us_p50;
  fig.rtt_us_p99 = stats.rtt_us_p99;
  fig.jitter_us_p50 = jitter.percentile(50);
  fig.jitter_us_p99 = jitter.percentile(99);
  client.disconnect();
  return fig;
}

// Peer: the bare libmodbus loop of the reference measurements (0x17, same registers).
LoopFigures run_peer(int port, double rate_hz, double seconds) {
  ModbusContext ctx = make_tcp_context("127.0.0.1", port);
  set_response_timeout(ctx.get(), 0.4 / rate_hz);
  // After a timeout, flush what arrives late (libmodbus's own recovery): without it one late
  // reply is read as the answer to the next request, and every exchange after it fails.
  modbus_set_error_recovery(ctx.get(), MODBUS_ERROR_RECOVERY_PROTOCOL);
  check_modbus(modbus_connect(ctx.get()), "bench peer: connect");
  LoopFigures fig;
  SampleWindow jitter(1 << 20);
  SampleWindow rtt(1 << 20);
  std::uint16_t counter = 0;
  run_periodic(rate_hz, seconds, jitter, fig, [&](double) {
    for (int unit : {1, 2}) {
      std::uint16_t write[3] = {0, 0, ++counter};
      std::uint16_t read[9];
      const double t0 = now_s();
      modbus_set_slave(ctx.get(), unit);
      ++fig.exchanges;
      if (modbus_write_and_read_registers(ctx.get(), 0, 3, write, 4, 9, read) == -1) {
        ++fig.faults;  // a failed exchange has no round trip
      } else {
        rtt.add((now_s() - t0) * 1e6);
      }
    }
  });
  fig.rtt_us_p50 = rtt.percentile(50);
  fig.rtt_us_p99 = rtt.percentile(99);
  fig.jitter_us_p50 = jitter.percentile(50);
  fig.jitter_us_p99 = jitter.percentile(99);
  return fig;
}

/// The calling thread's policy as the report states it, and its SCHED_FIFO priority (0: none).
std::pair<std::string, int> policy_in_force() {
  sched_param param{};
  const int policy = sched_getscheduler(0);
  sched_getparam(0, &param);
  if (policy == SCHED_FIFO)
    return {"SCHED_FIFO priority " + std::to_string(param.sched_priority), param.sched_priority};
  if (policy == SCHED_RR) return {"SCHED_RR priority " + std::to_string(param.sched_priority), 0};
  return {"SCHED_OTHER, no real-time priority", 0};
}

bench::Report run_bench(const std::vector<std::string>& args) {
  bench::Options options("servo", args);
  const double seconds = options.number("--seconds", 3.0, 0.1, 3600.0);
  const double rate_hz = options.number("--rate", 1000.0, 1.0, 100000.0);
  const long long fifo_priority = options.integer("--sched-fifo", 0, 0, 99);
  options.finish();
  // Before any thread starts: the amplifier's threads inherit the policy (Linux's default).
  std::optional<runtime::RealtimeScope> realtime;
  if (fifo_priority > 0) {
    graph::RealtimeSpec spec;
    spec.policy = graph::RealtimeSpec::Policy::fifo;
    spec.priority = static_cast<int>(fifo_priority);
    realtime.emplace(spec);
    for (const std::string& line : realtime->refused()) std::fprintf(stderr, "%s\n", line.c_str());
  }
  const auto [policy, priority] = policy_in_force();
  AmplifierServerConfig server_config;
  server_config.clock = ClockMode::own_thread;
  server_config.step_period_s = 1.0 / rate_hz;
  for (auto& axis : server_config.axes) axis.watchdog_timeout_s = 0.05;
  AmplifierServer server(server_config);
  const LoopFigures ours = run_ours(server.port(), rate_hz, seconds);
  const LoopFigures peer = run_peer(server.port(), rate_hz, seconds);

  bench::Report report;
  char title[128];
  std::snprintf(title, sizeof title, "servo: Modbus TCP loopback cycle, 2 axes, %.0f Hz, %.1f s",
                rate_hz, seconds);
  report.title = title;
  const std::string peer_name = "bare libmodbus 0x17 loop";
  report.rows.push_back(
      {"exchange round trip p50 (per axis)", "us", ours.rtt_us_p50, peer_name, peer.rtt_us_p50});
  report.rows.push_back(
      {"exchange round trip p99 (per axis)", "us", ours.rtt_us_p99, peer_name, peer.rtt_us_p99});
  report.rows.push_back(
      {"cycle wake-up jitter p99", "us", ours.jitter_us_p99, peer_name, peer.jitter_us_p99});
  report.json["modbus_rtt_us_p50"] = ours.rtt_us_p50;
  report.json["modbus_rtt_us_p99"] = ours.rtt_us_p99;
  report.json["cycle_jitter_us_p50"] = ours.jitter_us_p50;
  report.json["cycle_jitter_us_p99"] = ours.jitter_us_p99;
  report.json["cycle_overruns"] = static_cast<double>(ours.overruns);
  report.json["link_faults"] = static_cast<double>(ours.faults);
  report.json["link_fault_events"] = static_cast<double>(ours.fault_events);
  report.json["exchanges"] = static_cast<double>(ours.exchanges);
  report.json["link_faults_per_10k_exchanges"] =
      ours.exchanges > 0
          ? 1e4 * static_cast<double>(ours.fault_events) / static_cast<double>(ours.exchanges)
          : 0;
  report.json["peer_errors_per_10k_exchanges"] =
      peer.exchanges > 0
          ? 1e4 * static_cast<double>(peer.faults) / static_cast<double>(peer.exchanges)
          : 0;
  report.json["missed_cycles"] = static_cast<double>(ours.missed_cycles);
  report.json["late_replies"] = static_cast<double>(ours.late_replies);
  report.json["peer_modbus_rtt_us_p50"] = peer.rtt_us_p50;
  report.json["rtt_p50_ratio_vs_bare_libmodbus"] =
      peer.rtt_us_p50 > 0 ? ours.rtt_us_p50 / peer.rtt_us_p50 : 0;
  report.json["sched_fifo_priority"] = priority;
  report.notes.push_back(policy +
                         "; jitter = wake-up lateness against the absolute 1/rate schedule "
                         "(clock_nanosleep TIMER_ABSTIME)");
  report.notes.push_back("overruns " + std::to_string(ours.overruns) + ", link-fault cycles " +
                         std::to_string(ours.faults) + " (peer: " + std::to_string(peer.overruns) +
                         " overruns, " + std::to_string(peer.faults) + " failed exchanges of " +
                         std::to_string(peer.exchanges) + ")");
  char faults[256];
  std::snprintf(faults, sizeof faults,
                "link faults %llu in %llu exchanges (%.2f per 10,000); replies later than the "
                "%.2f ms timeout taken as missed cycles: %llu (%llu read late and dropped)",
                static_cast<unsigned long long>(ours.fault_events),
                static_cast<unsigned long long>(ours.exchanges),
                ours.exchanges > 0 ? 1e4 * static_cast<double>(ours.fault_events) /
                                         static_cast<double>(ours.exchanges)
                                   : 0.0,
                0.4e3 / rate_hz, static_cast<unsigned long long>(ours.missed_cycles),
                static_cast<unsigned long long>(ours.late_replies));
  report.notes.push_back(faults);
  return report;
}

}  // namespace
}  // namespace avs::servo

AVS_REGISTER_BENCH(servo, "servo",
                   "servo drive Modbus TCP loopback cycle at 1 kHz vs bare libmodbus "
                   "(--seconds S, --rate HZ, --sched-fifo PRIORITY)",
                   avs::servo::run_bench);
