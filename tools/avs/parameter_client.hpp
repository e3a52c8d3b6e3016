// The client end of ROS 2's parameter services (the container's, or a ROS 2 node's): what
// `avs param` uses. Requests go to rq/<node>/<service>Request with rmw_cyclonedds's request
// header, replies are matched by it on rr/<node>/<service>Reply.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "avs/runtime/dds.hpp"
#include "avs/runtime/parameter_messages.hpp"

namespace avs::cli {

/// A parameter as describe_parameters tells it.
struct ParameterDescription {
  std::string name;
  runtime::RosParameterType type = runtime::RosParameterType::not_set;
  std::string description;
  std::string constraints;
  bool read_only = false;
  std::optional<std::pair<double, double>> range;  ///< integer or floating-point range
};

class ParameterClient {
 public:
  /// `node`: fully qualified ("/decode"). Each call waits up to `timeout` for the node's
  /// service and its answer; throws runtime::Error saying which when there is none.
  ParameterClient(const runtime::dds::Participant& participant, std::string node,
                  std::chrono::milliseconds timeout);

  std::vector<std::string> list();
  /// nullopt where the node has no such parameter (or a type avs does not use).
  std::vector<std::optional<runtime::ParamValue>> get(const std::vector<std::string>& names);
  std::vector<ParameterDescription> describe(const std::vector<std::string>& names);
  /// Per parameter: "" when set, else the node's reason.
  std::vector<std::string> set(
      const std::vector<std::pair<std::string, runtime::ParamValue>>& values);

  const std::string& node() const { return node_; }

 private:
  template <class Request, class Response, class Fill>
  std::shared_ptr<Response> call(const char* service, Fill fill);

  const runtime::dds::Participant& participant_;
  std::string node_;
  std::chrono::milliseconds timeout_;
  std::int64_t sequence_ = 0;
};

/// Nodes offering parameter services that DDS discovery shows within `wait` (fully qualified,
/// sorted; our own participant and other partitions left out). Stops early once `wanted` is
/// among them.
std::vector<std::string> discover_parameter_nodes(const runtime::dds::Participant& participant,
                                                  std::chrono::milliseconds wait,
                                                  const std::string& wanted = {});

/// The fully qualified node a user means: "/x/decode" as given; "decode" -> "/decode", or the
/// one node whose last name is "decode". Throws runtime::Error when several match.
std::string resolve_node(const runtime::dds::Participant& participant, const std::string& name,
                         std::chrono::milliseconds wait);

}  // namespace avs::cli
