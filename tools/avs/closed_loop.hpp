// Runs the simulated closed loop (launch_config/closed_loop.yaml: sim_scene, sim_amplifier,
// servo_drive, decode, tracking, matching, run_recorder) in this process, in sim-time
// lockstep, with a progress line, then makes the run folder's report. Shared by `avs demo`
// and `avs experiments`.
#pragma once

#include <atomic>
#include <filesystem>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace avs::cli {

/// One run of the closed-loop graph: its arguments.
struct ClosedLoopRun {
  std::string scenario = "demo";          ///< written to meta.csv; selects the paper's figures
  std::string scene = "manipulator_ken";  ///< a name in launch_config/scenes/ or a YAML file
  std::string object = "ken";             ///< model matched (ken, cube, cylinder or a mesh file)
  std::string symmetry = "none";          ///< for the orientation error (summary.hpp)
  bool tracking = true;                   ///< false: the head holds still (Sec. 7.1.2)
  bool code_correction = true;            ///< Algorithm 1 on/off (Sec. 7.3)
  double duration_s = 3.0;                ///< simulated seconds
  /// Set: simulated time paced by the wall clock at this factor (the graph's clock in
  /// `realtime` mode, issue 16 section 4) instead of lockstep.
  std::optional<double> realtime_factor;
  std::string notes;
  std::map<std::string, std::string> extra_args;  ///< more graph arguments NAME -> VALUE
  std::filesystem::path dir;                      ///< run folder
  /// Set: a bag_recorder in the loop's container records `bag_topics` (comma-separated ROS
  /// names) into this MCAP file (overwritten), losing nothing: lockstep waits for it.
  std::filesystem::path bag;
  std::string bag_topics = "/camera/pattern";
};

struct ClosedLoopOutcome {
  int status = 1;            ///< 0 when the graph ran to its end (or was interrupted cleanly)
  bool interrupted = false;  ///< Ctrl-C / SIGTERM ended it early
};

/// The graph file avs runs (launch_config/closed_loop.yaml of the source tree).
std::filesystem::path closed_loop_graph();

/// A TCP port on 127.0.0.1 that nobody listens on right now (for the simulated amplifiers).
int free_tcp_port();

/// The DDS domain of closed-loop runs in this process: $AVS_DOMAIN_ID, or (unset) a private
/// one in 200-231, the same for every call. Called by run_closed_loop; call it before to
/// start something on the same domain (`avs demo --view`).
int choose_closed_loop_domain(const ClosedLoopRun& run, std::ostream& progress);

/// Runs the graph into run.dir, printing progress to `progress`. SIGINT/SIGTERM stop the run
/// early (what was recorded stays usable: a partial report); handled for the call only.
ClosedLoopOutcome run_closed_loop(const ClosedLoopRun& run, std::ostream& progress);

/// True once SIGINT or SIGTERM arrived during any run_closed_loop of this process.
bool interrupted_by_signal();

}  // namespace avs::cli
