// Internal to the graph loader: what is gathered across all files of one graph.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "avs/graph/yaml_reader.hpp"

namespace avs::graph::detail {

/// One end of a topic, for the type checks done once every file is read.
struct Endpoint {
  std::string topic;     ///< fully qualified ROS name
  std::string dds_type;  ///< "std_msgs::msg::dds_::String_"
  bool publisher = false;
  std::string component;
  std::string port;
  std::string container;
  SourceLocation where;      ///< the remap value, or the component's name
  runtime::QosProfile qos;   ///< the port's declared QoS or its override
  SourceLocation qos_where;  ///< the QoS override, or `where`
};

struct LoadState {
  Graph graph;
  Diagnostics diags;
  std::vector<std::string> include_stack;  ///< canonical paths, outermost first
  std::size_t included_files = 0;          ///< includes read so far (a repeated file counts again)
  bool include_budget_reported = false;
  std::map<std::string, SourceLocation> container_names;
  std::map<std::string, SourceLocation> component_names;
  std::vector<Endpoint> endpoints;
  std::optional<SourceLocation> master_where;  ///< where clock.master was written
  bool unnamed_container = false;              ///< a container without a valid name was reported
};

/// Reads the `containers:` list of one file into state.graph.containers.
void read_containers(LoadState& state, const FileReader& reader, const YAML::Node& node);

/// Reports endpoints of one topic whose types differ, and subscribers in one container
/// whose QoS no publisher in another container can satisfy (DDS would never match them).
void check_topics(LoadState& state);

}  // namespace avs::graph::detail
