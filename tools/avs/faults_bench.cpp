// avs bench faults: each container of the closed loop killed with SIGKILL in turn (issue 20
// section 5). `avs launch launch_config/closed_loop_processes.yaml` runs the loop with one
// process per stage and `respawn: always`; an in-process probe on the same DDS domain sees
// every pose, torque command, joint state, drive status and the simulated head's true torque.
// Per kill it measures how long the stage was gone and how long until its output came back,
// and the safety figures: after the tracking process dies, when the drive commands zero
// torque (and that it never commands torque from a command older than its timeout); after the
// drive dies, when the amplifiers' watchdog takes the torque off. At the end every file the
// recorder wrote (one per start) is read back.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <thread>

#include "avs/bench/report.hpp"
#include "avs/deploy/deployment.hpp"
#include "avs/mcap/reader.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/container.hpp"
#include "avs/runtime/error.hpp"
#include "avs/runtime/time.hpp"
#include "avs/servo/safety.hpp"
#include "avs_child.hpp"
#include "dds_environment.hpp"
#include "probe_container.hpp"

namespace avs::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::system_clock;  // the wall clock of the graph's stamps

std::int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// ---- the probe ----------------------------------------------------------------------------------

/// One sample as the probe saw it: its header stamp, when it arrived (both wall clock, ns),
/// and the largest torque magnitude it carries over the axes (0 for poses).
struct Seen {
  std::int64_t stamp_ns = 0;
  std::int64_t arrival_ns = 0;
  double torque_nm = 0;
};

/// What the probe saw, per topic, in arrival order.
struct Observed {
  std::vector<Seen> poses, commands, drive_status, head_state, joint_states;
};

template <class Seq>
double max_abs(const Seq& s) {
  double m = 0;
  for (std::uint32_t i = 0; i < s._length; ++i) m = std::max(m, std::abs(s._buffer[i]));
  return m;
}

class FaultProbe final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    runtime::QosProfile deep;
    deep.depth = 1000;
    return {
        .type = "bench_faults_probe",
        .description =
            "avs bench faults: keeps the stamp and arrival of every /object/pose, "
            "/head/torque_command, /head/drive_status, /head/joint_states and "
            "/sim/head_state",
        .subscribes = {
            runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose", deep),
            runtime::port<msgs::avs_msgs::JointTorqueCommand>("command", "/head/torque_command",
                                                              deep),
            runtime::port<msgs::avs_msgs::DriveStatus>("drive_status", "/head/drive_status", deep),
            runtime::port<msgs::sensor_msgs::JointState>("joint_states", "/head/joint_states",
                                                         deep),
            runtime::port<msgs::sensor_msgs::JointState>("head_state", "/sim/head_state", deep)}};
  }

  explicit FaultProbe(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) {
          keep(data_.poses, m->header.stamp, 0);
        });
    ctx.subscribe<msgs::avs_msgs::JointTorqueCommand>(
        "command", [this](runtime::SamplePtr<msgs::avs_msgs::JointTorqueCommand> m) {
          keep(data_.commands, m->header.stamp, max_abs(m->torque_nm));
        });
    ctx.subscribe<msgs::avs_msgs::DriveStatus>(
        "drive_status", [this](runtime::SamplePtr<msgs::avs_msgs::DriveStatus> m) {
          double torque = 0;
          for (std::uint32_t i = 0; i < m->axes._length; ++i) {
            torque = std::max(torque, std::abs(m->axes._buffer[i].commanded_torque_nm));
          }
          keep(data_.drive_status, m->header.stamp, torque);
        });
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states", [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) {
          keep(data_.joint_states, m->header.stamp, max_abs(m->effort));
        });
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "head_state", [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) {
          keep(data_.head_state, m->header.stamp, max_abs(m->effort));
        });
  }

  Observed data() const {
    std::lock_guard lock(mutex_);
    return data_;
  }

 private:
  template <class RosTime>
  void keep(std::vector<Seen>& into, const RosTime& stamp, double torque) {
    const Seen s{runtime::from_ros_time(stamp).ns, wall_ns(), torque};
    std::lock_guard lock(mutex_);
    into.push_back(s);
  }

  mutable std::mutex mutex_;
  Observed data_;
};

AVS_REGISTER_COMPONENT(FaultProbe);

// ---- options ----------------------------------------------------------------------------------

struct Options {
  double warm_up_s = 4;  ///< after the first pose, before the first kill
  double settle_s = 3;   ///< after a stage's output is back, before the next kill
  std::vector<std::string> containers{"recorder", "matcher", "vision", "control", "drive", "world"};
  double frame_rate_hz = 100;
  fs::path dir = "avs_bench_faults";
  fs::path graph;
};

Options parse_options(const std::vector<std::string>& raw) {
  Options o;
  o.graph = fs::path(AVS_SOURCE_DIR) / "launch_config" / "closed_loop_processes.yaml";
  bench::Options given("faults", raw, {"--help", "-h"});
  if (given.flag("--help") || given.flag("-h")) {
    std::printf(
        "avs bench faults [--json] [--containers=recorder,matcher,vision,control,drive,world]\n"
        "                 [--warm-up=S] [--settle=S] [--frame-rate=HZ] [--dir=DIR] [--graph=FILE]\n"
        "Launches launch_config/closed_loop_processes.yaml (one process per stage, respawn:\n"
        "always), waits S s after the first pose, then kills each named container with SIGKILL\n"
        "in turn, waiting for its output to come back and --settle s more before the next.\n"
        "Prints per kill: time gone, time to recover, the drive's zero-torque time (tracking\n"
        "killed), the amplifiers' (drive killed), and every recorder file read back.\n"
        "Writes the launch log and the recordings to DIR (default ./avs_bench_faults). FILE:\n"
        "another graph with the same container names and args.\n");
    std::exit(0);
  }
  o.warm_up_s = given.number("--warm-up", o.warm_up_s, 0.0, 600.0);
  o.settle_s = given.number("--settle", o.settle_s, 0.0, 600.0);
  o.frame_rate_hz = given.number("--frame-rate", o.frame_rate_hz, 10.0, 1000.0);
  o.dir = given.text("--dir", o.dir.string());
  o.graph = given.text("--graph", o.graph.string());
  if (const std::string v = given.text("--containers", ""); !v.empty()) {
    const std::vector<std::string> known = o.containers;
    o.containers.clear();
    std::stringstream ss(v);
    for (std::string c; std::getline(ss, c, ',');) {
      if (std::find(known.begin(), known.end(), c) == known.end()) {
        throw runtime::Error("avs bench faults: unknown container '" + c +
                             "' (recorder, matcher, vision, control, drive, world)");
      }
      o.containers.push_back(c);
    }
  }
  given.finish();
  return o;
}

// ---- the processes ------------------------------------------------------------------------------

// ---- one kill -------------------------------------------------------------------------------

struct KillResult {
  std::string container;
  bool respawned = false, recovered = false;
  double gone_s = NAN;        ///< SIGKILL -> the launcher's new process seen
  double recovery_s = NAN;    ///< SIGKILL -> the first output of the new process
  double output_gap_s = NAN;  ///< longest gap between two arrivals of the stage's output
  std::string output;         ///< what "output" means for this stage
  // Tracking killed: the drive's reaction, from its own status (every cycle).
  double zero_torque_after_ms = NAN;      ///< last command's stamp -> first zero status
  double command_period_ms = NAN;         ///< median period of the commands before the kill
  double last_command_torque_nm = NAN;    ///< largest axis torque of the last command
  std::int64_t stale_torque_cycles = -1;  ///< torque commanded from a command older than limit
  // Drive killed: the amplifiers' watchdog, from the true head state.
  double amplifier_zero_after_ms = NAN;  ///< the drive's last status -> torque off
  double servo_gap_s = NAN;              ///< longest gap in torque commands (matcher killed)
};

// servo_drive's command_timeout_s default (the graph leaves it).
const double kCommandTimeoutS = servo::CommandFreshness{}.timeout_s;

double median_period_ms(const std::vector<Seen>& v, std::int64_t before_ns, std::size_t n) {
  std::vector<double> periods;
  for (std::size_t i = 1; i < v.size(); ++i) {
    if (v[i].stamp_ns >= before_ns) break;
    periods.push_back(1e-6 * static_cast<double>(v[i].stamp_ns - v[i - 1].stamp_ns));
  }
  if (periods.size() > n) periods.erase(periods.begin(), periods.end() - static_cast<long>(n));
  if (periods.empty()) return NAN;
  std::nth_element(periods.begin(), periods.begin() + static_cast<long>(periods.size() / 2),
                   periods.end());
  return periods[periods.size() / 2];
}

double longest_gap_s(const std::vector<Seen>& v, std::int64_t from_ns, std::int64_t to_ns) {
  double gap = 0;
  std::int64_t last = from_ns;
  for (const Seen& s : v) {
    if (s.arrival_ns < from_ns) continue;
    if (s.arrival_ns > to_ns) break;
    gap = std::max(gap, 1e-9 * static_cast<double>(s.arrival_ns - last));
    last = s.arrival_ns;
  }
  return std::max(gap, 1e-9 * static_cast<double>(to_ns - last));
}

/// The stage's output topic(s) in the probe's data.
std::vector<const std::vector<Seen>*> outputs_of(const std::string& container, const Observed& d,
                                                 std::string& what) {
  if (container == "control") {
    what = "/head/torque_command";
    return {&d.commands};
  }
  if (container == "drive") {
    what = "/head/joint_states";
    return {&d.joint_states};
  }
  if (container == "world") {
    what = "/object/pose and /head/joint_states";
    return {&d.poses, &d.joint_states};
  }
  what = "/object/pose";
  return {&d.poses};
}

/// The first arrival, in `v`, of a sample stamped after `after_ns`; -1 when none.
std::int64_t first_arrival_after(const std::vector<Seen>& v, std::int64_t after_ns) {
  for (const Seen& s : v) {
    if (s.stamp_ns > after_ns) return s.arrival_ns;
  }
  return -1;
}

/// In `v`, the stamp from which the torque stays zero over (after_ns, until_ns): the sample
/// after the last non-zero one (the first one after after_ns when all are zero); -1 when the
/// last one is not zero or there is none.
std::int64_t zero_from(const std::vector<Seen>& v, std::int64_t after_ns, std::int64_t until_ns) {
  std::int64_t zero_ns = -1;
  for (const Seen& s : v) {
    if (s.stamp_ns <= after_ns || (until_ns > 0 && s.stamp_ns >= until_ns)) continue;
    if (s.torque_nm != 0) {
      zero_ns = -1;
    } else if (zero_ns < 0) {
      zero_ns = s.stamp_ns;
    }
  }
  return zero_ns;
}

void measure_safety(KillResult& r, const Observed& d, std::int64_t kill_ns,
                    std::int64_t respawn_ns) {
  if (r.container == "control") {
    // The last command of the killed process, the first of the new one.
    std::int64_t last_ns = -1, next_ns = -1;
    for (const Seen& c : d.commands) {
      if (c.stamp_ns < kill_ns) {
        last_ns = c.stamp_ns;
        r.last_command_torque_nm = c.torque_nm;
      }
      if (c.stamp_ns > respawn_ns && next_ns < 0) next_ns = c.stamp_ns;
    }
    r.command_period_ms = median_period_ms(d.commands, kill_ns, 200);
    if (last_ns < 0) return;
    std::int64_t stale = 0;
    for (const Seen& s : d.drive_status) {
      if (s.stamp_ns <= last_ns || (next_ns > 0 && s.stamp_ns >= next_ns)) continue;
      // The drive's status is stamped with the cycle time its torque was chosen at.
      if (s.torque_nm != 0 &&
          s.stamp_ns - last_ns > static_cast<std::int64_t>(kCommandTimeoutS * 1e9)) {
        ++stale;
      }
    }
    r.stale_torque_cycles = stale;
    if (const std::int64_t zero_ns = zero_from(d.drive_status, last_ns, next_ns); zero_ns > 0) {
      r.zero_torque_after_ms = 1e-6 * static_cast<double>(zero_ns - last_ns);
    }
  } else if (r.container == "drive") {
    std::int64_t last_ns = -1, next_ns = -1;
    for (const Seen& s : d.drive_status) {
      if (s.stamp_ns < kill_ns) last_ns = s.stamp_ns;
      if (s.stamp_ns > respawn_ns && next_ns < 0) next_ns = s.stamp_ns;
    }
    if (last_ns < 0) return;
    if (const std::int64_t zero_ns = zero_from(d.head_state, last_ns, next_ns); zero_ns > 0) {
      r.amplifier_zero_after_ms = 1e-6 * static_cast<double>(zero_ns - last_ns);
    }
  } else if (r.container == "matcher" || r.container == "recorder") {
    r.servo_gap_s = longest_gap_s(d.commands, kill_ns, respawn_ns);
  }
}

/// A file the recorder wrote, read back.
struct RecordedFile {
  fs::path file;
  std::uint64_t messages = 0;
  bool readable = false, had_summary = false;
  std::string error;
  double first_s = 0, last_s = 0;  ///< log times, wall clock
};

RecordedFile read_back(const fs::path& file) {
  RecordedFile f;
  f.file = file;
  mcap::Reader reader;
  mcap::Status s = reader.open(file);
  if (s.ok()) {
    f.had_summary = reader.read_summary().ok();
    mcap::ReadOptions options;
    options.allow_truncated = true;  // a recorder killed with SIGKILL has no summary
    s = reader.read_messages(
        [&](const mcap::MessageView& m) {
          const double t = 1e-9 * static_cast<double>(m.log_time);
          if (f.messages == 0) f.first_s = t;
          f.last_s = std::max(f.last_s, t);
          ++f.messages;
          return true;
        },
        options);
  }
  f.readable = s.ok();
  if (!s.ok()) f.error = s.to_string();
  return f;
}

// ---- the bench --------------------------------------------------------------------------------

/// Waits until `done()` or `timeout_s`; false on timeout.
bool wait_for(const std::function<bool()>& done, double timeout_s) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

bench::Report faults_bench(const std::vector<std::string>& args) {
  const Options o = parse_options(args);
  const fs::path dir = fs::absolute(o.dir);
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".mcap") fs::remove(e.path());  // the recorder keeps old files
  }
  const int domain = domain_or_environment(183);
  const int port = 20000 + domain;  // Modbus port of this run's simulated amplifiers
  deploy::Deployment d;
  d.hosts.push_back(deploy::Host{"local", "", "lo", {}, {}});
  const std::string xml = deploy::cyclone_config(d, d.hosts[0], "bench");

  bench::Report report;
  const std::string load_before = bench::load_average();
  std::ostringstream title;
  title << "avs bench faults: the closed loop in six processes (" << o.graph.filename().string()
        << ", " << o.frame_rate_hz << " fps, wall clock), each container killed with SIGKILL "
        << "in turn and restarted by avs launch; load average before: " << load_before;
  report.title = title.str();

  // The probe first: it sees the first samples of every stage.
  ProbeContainer<FaultProbe> probe_container(dir, "bench_faults_probe", xml, domain,
                                             "avs bench faults");
  const FaultProbe* probe = &probe_container.probe();

  const fs::path bag = dir / "loop.mcap";
  const fs::path launch_log = dir / "launch.log";
  std::vector<KillResult> kills;
  {
    AvsChild launcher(
        {"launch", o.graph.string(), "bag:=" + bag.string(), "port:=" + std::to_string(port),
         "frame_rate_hz:=" + std::to_string(o.frame_rate_hz)},
        xml, domain, launch_log, "avs bench faults");
    std::fprintf(stderr, "avs bench faults: launched %s (log %s)\n", o.graph.c_str(),
                 launch_log.c_str());
    if (!wait_for([&] { return !probe->data().poses.empty() || !launcher.running(); }, 180) ||
        !launcher.running()) {
      throw runtime::Error("avs bench faults: no pose within 180 s of the launch; see " +
                           launch_log.string());
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(o.warm_up_s));
    // Kill only a loop that runs: every stage's output seen in the last second.
    {
      const Observed now = probe->data();
      const std::int64_t recent = wall_ns() - 1'000'000'000;
      std::string missing;
      for (const auto& [topic, v] :
           {std::pair{"/object/pose", &now.poses}, std::pair{"/head/torque_command", &now.commands},
            std::pair{"/head/joint_states", &now.joint_states},
            std::pair{"/head/drive_status", &now.drive_status},
            std::pair{"/sim/head_state", &now.head_state}}) {
        if (v->empty() || v->back().arrival_ns < recent) missing += std::string(" ") + topic;
      }
      if (!missing.empty()) {
        throw runtime::Error("avs bench faults: the loop does not run before the first kill (no" +
                             missing + " in the last second); see " + launch_log.string());
      }
    }
    for (const std::string& name : o.containers) {
      KillResult r;
      r.container = name;
      const pid_t old_pid = container_pid(launcher.pid(), name);
      if (old_pid <= 0) {
        report.notes.push_back("container '" + name + "' not found; not killed");
        continue;
      }
      const std::int64_t kill_ns = wall_ns();
      kill(old_pid, SIGKILL);
      std::fprintf(stderr, "avs bench faults: killed '%s' (pid %d)\n", name.c_str(), old_pid);
      pid_t new_pid = -1;
      r.respawned = wait_for(
          [&] {
            new_pid = container_pid(launcher.pid(), name);
            return new_pid > 0 && new_pid != old_pid;
          },
          60);
      const std::int64_t respawn_ns = wall_ns();
      if (r.respawned) r.gone_s = 1e-9 * static_cast<double>(respawn_ns - kill_ns);
      std::string what;
      std::int64_t back_ns = -1;
      if (r.respawned && name == "recorder") {
        // Its output is a new file that grows past its header (a chunk written).
        r.output = "a new MCAP file with a chunk";
        const fs::path next = bag.parent_path() / (bag.stem().string() + ".1.mcap");
        r.recovered = wait_for(
            [&] {
              std::error_code ec;
              const auto size = fs::file_size(next, ec);
              return !ec && size > 1000;
            },
            60);
        back_ns = wall_ns();
      } else if (r.respawned) {
        r.recovered = wait_for(
            [&] {
              const Observed now = probe->data();
              std::int64_t latest = 0;
              for (const auto* v : outputs_of(name, now, what)) {
                const std::int64_t t = first_arrival_after(*v, respawn_ns);
                if (t < 0) return false;
                latest = std::max(latest, t);
              }
              back_ns = latest;
              return true;
            },
            120);
        r.output = what;
      }
      if (r.recovered) {
        r.recovery_s = 1e-9 * static_cast<double>(back_ns - kill_ns);
        std::fprintf(stderr, "avs bench faults: '%s' back after %.2f s\n", name.c_str(),
                     r.recovery_s);
      } else {
        std::fprintf(stderr, "avs bench faults: '%s' did NOT come back\n", name.c_str());
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(o.settle_s));
      const Observed seen = probe->data();
      if (name != "recorder") {
        double gap = 0;
        for (const auto* v : outputs_of(name, seen, what)) {
          gap = std::max(gap, longest_gap_s(*v, kill_ns - 1'000'000'000, wall_ns()));
        }
        r.output_gap_s = gap;
      }
      measure_safety(r, seen, kill_ns, respawn_ns);
      kills.push_back(r);
    }
    launcher.terminate();
    const int status = launcher.wait();
    if (!WIFEXITED(status) && !WIFSIGNALED(status)) {
      report.notes.push_back("avs launch ended abnormally (status " + std::to_string(status) + ")");
    }
  }
  probe_container.stop();

  // ---- the table ----
  double max_recovery = 0;
  int recovered = 0;
  for (const KillResult& r : kills) {
    const std::string k = "kill." + r.container + ".";
    report.rows.push_back({r.container + " killed: gone (until restarted)", "s", r.gone_s, "", 0});
    report.rows.push_back(
        {r.container + " killed: recovered (" + r.output + " again)", "s", r.recovery_s, "", 0});
    report.json[k + "respawned"] = r.respawned ? 1 : 0;
    report.json[k + "recovered"] = r.recovered ? 1 : 0;
    report.json[k + "gone_s"] = r.gone_s;
    report.json[k + "recovery_s"] = r.recovery_s;
    report.json[k + "output_gap_s"] = r.output_gap_s;
    if (r.recovered) {
      ++recovered;
      max_recovery = std::max(max_recovery, r.recovery_s);
    }
    if (r.container == "control") {
      const double periods = r.zero_torque_after_ms / r.command_period_ms;
      report.rows.push_back({"control killed: drive at zero torque after the last command", "ms",
                             r.zero_torque_after_ms, "issue 20: within 2 command periods",
                             2 * r.command_period_ms});
      report.rows.push_back({"control killed: torque from commands older than the timeout",
                             "cycles", static_cast<double>(r.stale_torque_cycles), "", 0});
      report.json[k + "zero_torque_after_ms"] = r.zero_torque_after_ms;
      report.json[k + "zero_torque_after_command_periods"] = periods;
      report.json[k + "command_period_ms"] = r.command_period_ms;
      report.json[k + "last_command_torque_nm"] = r.last_command_torque_nm;
      report.json[k + "stale_torque_cycles"] = static_cast<double>(r.stale_torque_cycles);
    }
    if (r.container == "drive") {
      report.rows.push_back({"drive killed: amplifiers' torque off after its last cycle", "ms",
                             r.amplifier_zero_after_ms, "watchdog_timeout_s", 100});
      report.json[k + "amplifier_zero_torque_after_ms"] = r.amplifier_zero_after_ms;
    }
    if (!std::isnan(r.servo_gap_s)) {
      report.rows.push_back(
          {r.container + " killed: longest gap in torque commands", "s", r.servo_gap_s, "", 0});
      report.json[k + "servo_gap_s"] = r.servo_gap_s;
    }
  }
  report.json["containers_killed"] = static_cast<double>(kills.size());
  report.json["containers_recovered"] = recovered;
  report.json["recovery_s_max"] = max_recovery;

  // ---- every recording read back ----
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".mcap") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  int readable = 0;
  std::uint64_t messages = 0;
  for (const fs::path& file : files) {
    const RecordedFile f = read_back(file);
    std::ostringstream note;
    note << "recording " << file.filename().string() << ": "
         << (f.readable ? "readable" : "NOT readable (" + f.error + ")") << ", " << f.messages
         << " message(s), " << (f.had_summary ? "closed (summary)" : "no summary (killed)");
    if (f.messages > 0) note << ", " << (f.last_s - f.first_s) << " s";
    report.notes.push_back(note.str());
    readable += f.readable ? 1 : 0;
    messages += f.messages;
  }
  report.json["recordings"] = static_cast<double>(files.size());
  report.json["recordings_readable"] = readable;
  report.json["recorded_messages"] = static_cast<double>(messages);
  report.json["load_average_1min_before"] = std::atof(load_before.c_str());
  report.json["load_average_1min_after"] = std::atof(bench::load_average().c_str());
  report.notes.push_back(
      "gone: SIGKILL until avs launch's new process is seen (its backoff_s 0.2 s and the "
      "launcher's poll); recovered: until the first output of the new process (DDS discovery, "
      "component start-up, for the world the drive's reconnection). The drive's times are "
      "its own cycle stamps (/head/drive_status every cycle); the amplifiers' is "
      "/sim/head_state. Launch log: " +
      launch_log.string());
  return report;
}

AVS_REGISTER_BENCH(faults, "faults",
                   "each container of the closed loop killed with SIGKILL in turn: time to "
                   "recover, zero torque, recordings readable",
                   faults_bench);

}  // namespace
}  // namespace avs::cli
