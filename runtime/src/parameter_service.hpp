// The parameter services of a container's components (ROS 2's, over plain DDS): for each
// component a node with get/set/list/describe_parameters and get_parameter_types on
// rq/<node>/<service>Request -> rr/<node>/<service>Reply (rcl_interfaces types, the
// rmw_cyclonedds request header), and /parameter_events on every change. Reads are answered
// on the service's own thread; a change is checked there (name, dynamic, type, range) and
// applied on the component's thread between two callbacks; its reply goes out once applied.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "avs/runtime/component.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/time.hpp"

namespace avs::runtime {

/// One node the service answers for: a component of the container.
class ParameterNode {
 public:
  virtual ~ParameterNode() = default;
  /// Fully qualified ROS node name, "/decode" (the graph's namespace + the component's name).
  virtual const std::string& node_name() const = 0;
  virtual const ComponentSpec& node_spec() const = 0;
  /// The current values (thread-safe).
  virtual ParameterValues snapshot() const = 0;
  /// Applies `values` on the component's thread between two callbacks, then calls
  /// `done("")`, or `done(reason)` when the component refused; `done` runs on that thread.
  virtual void apply_later(ParameterValues values, std::vector<std::string> changed,
                           std::function<void(const std::string&)> done) = 0;
};

class ParameterService {
 public:
  ParameterService(const dds::Participant& participant, std::vector<ParameterNode*> nodes,
                   std::function<Time()> clock);
  ~ParameterService();
  ParameterService(const ParameterService&) = delete;
  ParameterService& operator=(const ParameterService&) = delete;

  /// The request readers and reply writers serving `node`, and the /parameter_events writer
  /// (ros_discovery_info lists them as the node's).
  std::vector<dds_entity_t> readers_of(const ParameterNode& node) const;
  std::vector<dds_entity_t> writers_of(const ParameterNode& node) const;

  /// Starts answering (a thread of its own); stop() or the destructor ends it.
  void start();
  void stop();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace avs::runtime
