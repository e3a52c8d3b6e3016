// The Foxglove WebSocket protocol (subprotocol `foxglove.websocket.v1`), as far as `avs view`
// speaks it: the server's JSON messages (serverInfo, status, advertise, unadvertise), the
// binary Message Data frame header, and the client's subscribe/unsubscribe requests.
// Plain C++ (no sockets, no DDS): every function here is a pure encoding or parsing step.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace avs::view {

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

using ChannelId = std::uint32_t;
using SubscriptionId = std::uint32_t;

/// One advertised topic.
struct Channel {
  ChannelId id = 0;
  std::string topic;             ///< ROS name, e.g. "/depth/image"
  std::string encoding = "cdr";  ///< message encoding
  std::string schema_name;       ///< ROS type, e.g. "sensor_msgs/msg/Image"
  std::string schema;            ///< the ros2msg definition text
  std::string schema_encoding = "ros2msg";
  bool is_image = false;  ///< subject to a client's max_rate_hz
};

enum class StatusLevel : int { info = 0, warning = 1, error = 2 };

std::string server_info_json(std::string_view name, std::string_view session_id);
std::string status_json(StatusLevel level, std::string_view message);
std::string advertise_json(std::span<const Channel> channels);
std::string unadvertise_json(std::span<const ChannelId> ids);

/// Binary opcode 0x01 (Message Data): opcode, subscription id (u32 LE), receive time
/// (u64 ns LE); the payload (the CDR bytes) follows in the same WebSocket frame.
inline constexpr std::size_t kMessageDataHeaderSize = 13;
std::array<std::uint8_t, kMessageDataHeaderSize> message_data_header(SubscriptionId id,
                                                                     std::uint64_t receive_ns);

struct Subscribe {
  struct Item {
    SubscriptionId id = 0;
    ChannelId channel = 0;
  };
  std::vector<Item> subscriptions;
};
struct Unsubscribe {
  std::vector<SubscriptionId> ids;
};
/// A client text message this server does not accept, with the reason sent back.
struct Rejected {
  std::string reason;
};
using ClientRequest = std::variant<Subscribe, Unsubscribe, Rejected>;

/// Parses one client text message. Never throws: malformed JSON, a missing or mistyped field,
/// or an operation this server does not offer (clientPublish, parameters, services, ...)
/// comes back as Rejected with a reason.
ClientRequest parse_client_message(std::string_view text);

/// Options a client asks for in the query of the WebSocket URL, e.g.
/// `ws://host:8765/?max_rate_hz=10`.
struct ClientOptions {
  double max_rate_hz = 0;  ///< image topics at most this often (0: every message)
};
/// Parses the request target ("/", "/?max_rate_hz=10"). Unknown keys or bad numbers make
/// `error` non-empty (the connection is refused with that reason).
struct ParsedTarget {
  ClientOptions options;
  std::string error;
};
ParsedTarget parse_request_target(std::string_view target, const ClientOptions& defaults);

}  // namespace avs::view
