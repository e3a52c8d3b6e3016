// Component parameters in ROS 2's rcl_interfaces messages (idl/rcl_interfaces*.idl): the
// values, descriptors and service topic names that the container's parameter service and
// `avs param` exchange, the way rclcpp's parameter services and `ros2 param` do
// (docs/operate.md).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/parameters.hpp"
#include "avs/runtime/qos.hpp"

namespace avs::runtime {

/// rcl_interfaces/msg/ParameterType constants.
enum class RosParameterType : std::uint8_t {
  not_set = 0,
  boolean = 1,
  integer = 2,
  real = 3,
  string = 4,
  byte_array = 5,
  bool_array = 6,
  integer_array = 7,
  real_array = 8,
  string_array = 9,
};

RosParameterType ros_parameter_type(ParamType type);
/// nullopt for types avs parameters do not have (byte, bool, integer and string arrays).
std::optional<ParamType> param_type(RosParameterType type);
/// "integer", "double array", ... (ros2 param's words), "not set" for 0.
std::string to_string(RosParameterType type);

/// Fills `out` (strings and sequences allocated with dds_alloc, freed with the sample).
void to_message(const ParamValue& value, msgs::rcl_interfaces::ParameterValue& out);
/// The value in avs terms: a number, integer, bool, string, or a list of numbers (an integer
/// array becomes a list of numbers); nullopt for "not set" and the other array types.
std::optional<ParamValue> from_message(const msgs::rcl_interfaces::ParameterValue& value);

/// The descriptor ROS 2 tools show: type, description (with the unit), the range
/// (integer_range / floating_point_range; unbounded sides at the type's limits), read_only for
/// restart-only parameters, and in additional_constraints what avs adds: range of list
/// elements, choices, and whether the parameter is live.
void to_descriptor(const ParamSpec& spec, msgs::rcl_interfaces::ParameterDescriptor& out);

/// The names of the parameter services a node offers (ROS 2's, minus set_parameters_atomically).
inline constexpr const char* kParameterServices[] = {"get_parameters", "set_parameters",
                                                     "list_parameters", "describe_parameters",
                                                     "get_parameter_types"};

/// DDS topic of the requests to / replies from `service` of node `node` (fully qualified,
/// "/decode"): "rq/decode/get_parametersRequest", "rr/decode/get_parametersReply".
std::string parameter_request_topic(std::string_view node, std::string_view service);
std::string parameter_reply_topic(std::string_view node, std::string_view service);
/// The node whose service `dds_topic` belongs to ("/decode"), or "" when it is not a
/// parameter service topic (`avs param list` finds the nodes this way).
std::string parameter_service_node(std::string_view dds_topic);

/// rmw_qos_profile_services_default (reliable, volatile, keep last 10).
QosProfile service_qos();
/// rmw_qos_profile_parameter_events (reliable, volatile, keep last 1000), on rt/parameter_events.
QosProfile parameter_events_qos();
inline constexpr const char* kParameterEventsTopic = "rt/parameter_events";

}  // namespace avs::runtime
