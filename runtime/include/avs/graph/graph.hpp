// A launch graph after loading and validation: containers (processes) holding
// component instances. Produced by load_graph(), consumed by `avs launch` and containers.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "avs/runtime/parameters.hpp"
#include "avs/runtime/qos.hpp"
#include "avs/runtime/time.hpp"

namespace avs::runtime {
struct PortSpec;  // avs/runtime/component.hpp
}  // namespace avs::runtime

namespace avs::graph {

struct SourceLocation {
  std::string file;
  int line = 0;    ///< 1-based
  int column = 0;  ///< 1-based
  std::string str() const {
    return file + ":" + std::to_string(line) + ":" + std::to_string(column);
  }
};

/// One validation error: "file:line:column: error: <message>".
struct Diagnostic {
  SourceLocation where;
  std::string message;
  std::string str() const { return where.str() + ": error: " + message; }
};

struct ComponentInstance {
  std::string type;                                ///< registered component type
  std::string name;                                ///< unique in the graph
  runtime::ParameterValues parameters;             ///< every declared parameter, defaults filled in
  std::map<std::string, std::string> remaps;       ///< port -> ROS topic name (as written)
  std::map<std::string, runtime::QosProfile> qos;  ///< port -> QoS override
  SourceLocation where;
};

enum class ExecutorKind { single_threaded, thread_per_component };

struct RespawnPolicy {
  enum class Kind { never, on_failure, always } kind = Kind::never;
  int max_restarts = 5;
  double backoff_s = 1.0;  ///< doubled after each restart
};

/// Real-time settings of a container's threads (issue 16 section 3, docs/realtime.md).
struct RealtimeSpec {
  enum class Policy { other, fifo, rr } policy = Policy::other;
  int priority = 0;          ///< 1-99 with fifo and rr, 0 with other
  std::vector<int> cpus;     ///< CPU affinity of every thread; empty: any CPU
  bool lock_memory = false;  ///< mlockall: no page fault stalls a frame
  bool any() const { return policy != Policy::other || !cpus.empty() || lock_memory; }
};

struct ContainerSpec {
  std::string name;
  std::string host;  ///< empty: any host
  ExecutorKind executor = ExecutorKind::single_threaded;
  RealtimeSpec realtime;
  RespawnPolicy respawn;
  std::vector<ComponentInstance> components;
  SourceLocation where;
};

/// How time flows. `wall`: real time. `sim`: the `master` container runs a simulated clock
/// (lockstep: as fast as possible, advancing only when every component there is idle;
/// realtime: at `real_time_factor` x wall speed) and publishes it on /clock; other
/// containers follow /clock.
struct ClockSpec {
  enum class Source { wall, sim } source = Source::wall;
  enum class Mode { lockstep, realtime } mode = Mode::lockstep;
  double real_time_factor = 1.0;
  std::string master;                ///< container name; default: the first container
  std::optional<double> duration_s;  ///< stop the graph after this much (sim or wall) time
  /// Lockstep: before time advances, a writer with a recorder (`avs bag record`) among its
  /// matched readers waits until the recorder has acknowledged what it may otherwise overwrite,
  /// so the recording is complete whatever the load (issue 20 section 6, docs/bag.md).
  bool wait_for_recorders = true;
  /// Lockstep with wait_for_recorders: before the first step, wait up to this long (s) for a
  /// recorder to match one of the container's writers. DDS discovery can take longer than a
  /// light graph's whole run, so a recording started first may otherwise miss the start (or
  /// all of it); 0 (the default): start at once.
  double recorder_start_timeout_s = 0.0;
};

struct Graph {
  std::string file;
  std::string ns = "/";  ///< namespace for relative topic names
  int domain_id = 0;
  /// DDS partition of every reader and writer; not in graph files: the command line sets it
  /// ($AVS_PARTITION, which `avs launch` sets from a deployment's `partition`).
  std::string partition;
  ClockSpec clock;
  std::vector<ContainerSpec> containers;
  std::map<std::string, std::string> args;  ///< final argument values (of the top-level file)
  std::vector<std::string> files;           ///< every file loaded, top-level first

  const ContainerSpec* find_container(const std::string& name) const {
    for (const auto& c : containers) {
      if (c.name == name) return &c;
    }
    return nullptr;
  }
};

/// Result of loading: a graph, or every error found (nothing is started on errors).
struct LoadResult {
  std::optional<Graph> graph;
  std::vector<Diagnostic> errors;
  bool ok() const { return graph.has_value() && errors.empty(); }
};

/// Loads and validates `file` with argument overrides ("speed" -> "0.5" from `speed:=0.5`),
/// against the component types in runtime::ComponentRegistry.
/// All errors of the whole file set are collected (format and error classes: docs/graphs.md).
LoadResult load_graph(const std::string& file, const std::map<std::string, std::string>& args);

/// Pulls `name:=value` words (launch argument overrides) out of `words`; the other words
/// go to `rest` in order (when `rest` is not null). A later override of a name wins.
std::map<std::string, std::string> parse_arg_overrides(const std::vector<std::string>& words,
                                                       std::vector<std::string>* rest);

/// The fully qualified ROS topic name of `port` of `component`: its remap (or the port's
/// default topic) resolved against the graph's namespace, e.g. "/chat". Throws
/// runtime::Error on an invalid name (load_graph has already reported those).
std::string port_topic(const Graph& graph, const ComponentInstance& component,
                       const runtime::PortSpec& port);

}  // namespace avs::graph
