#include "avs/view/protocol.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

namespace avs::view {

namespace {

using nlohmann::json;

/// True when `value` is an integer in [0, 2^32), stored in `out`.
bool as_u32(const json& value, std::uint32_t& out) {
  if (!value.is_number_integer() || value.get<std::int64_t>() < 0 ||
      value.get<std::int64_t>() > std::numeric_limits<std::uint32_t>::max()) {
    return false;
  }
  out = static_cast<std::uint32_t>(value.get<std::int64_t>());
  return true;
}

/// An unsigned 32-bit id from `object[key]`, or an error naming the key.
bool read_id(const json& object, const char* key, std::uint32_t& out, std::string& error) {
  const auto it = object.find(key);
  if (it == object.end()) {
    error = std::string("missing \"") + key + "\"";
    return false;
  }
  if (!as_u32(*it, out)) {
    error = std::string("\"") + key + "\" must be an integer in [0, 2^32)";
    return false;
  }
  return true;
}

ClientRequest parse_subscribe(const json& message) {
  const auto it = message.find("subscriptions");
  if (it == message.end() || !it->is_array()) {
    return Rejected{"subscribe: \"subscriptions\" must be an array"};
  }
  Subscribe s;
  for (const json& item : *it) {
    if (!item.is_object()) return Rejected{"subscribe: each subscription must be an object"};
    Subscribe::Item parsed;
    std::string error;
    if (!read_id(item, "id", parsed.id, error) ||
        !read_id(item, "channelId", parsed.channel, error)) {
      return Rejected{"subscribe: " + error};
    }
    s.subscriptions.push_back(parsed);
  }
  return s;
}

ClientRequest parse_unsubscribe(const json& message) {
  const auto it = message.find("subscriptionIds");
  if (it == message.end() || !it->is_array()) {
    return Rejected{"unsubscribe: \"subscriptionIds\" must be an array"};
  }
  Unsubscribe u;
  for (const json& id : *it) {
    SubscriptionId parsed = 0;
    if (!as_u32(id, parsed)) {
      return Rejected{"unsubscribe: subscription ids must be integers in [0, 2^32)"};
    }
    u.ids.push_back(parsed);
  }
  return u;
}

}  // namespace

std::string server_info_json(std::string_view name, std::string_view session_id) {
  // No optional capability: no client publishing, parameters, services or time messages.
  json j = {{"op", "serverInfo"},
            {"name", name},
            {"capabilities", json::array()},
            {"supportedEncodings", json::array()},
            {"metadata", json::object()},
            {"sessionId", session_id}};
  return j.dump();
}

std::string status_json(StatusLevel level, std::string_view message) {
  json j = {{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}};
  // Replace rather than throw on invalid UTF-8 (a reason may quote what a client sent).
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string advertise_json(std::span<const Channel> channels) {
  json list = json::array();
  for (const Channel& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  json j = {{"op", "advertise"}, {"channels", std::move(list)}};
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string unadvertise_json(std::span<const ChannelId> ids) {
  json j = {{"op", "unadvertise"}, {"channelIds", std::vector<ChannelId>(ids.begin(), ids.end())}};
  return j.dump();
}

std::array<std::uint8_t, kMessageDataHeaderSize> message_data_header(SubscriptionId id,
                                                                     std::uint64_t receive_ns) {
  std::array<std::uint8_t, kMessageDataHeaderSize> h{};
  h[0] = 0x01;  // Message Data
  for (int i = 0; i < 4; ++i) h[1 + i] = static_cast<std::uint8_t>(id >> (8 * i));
  for (int i = 0; i < 8; ++i) h[5 + i] = static_cast<std::uint8_t>(receive_ns >> (8 * i));
  return h;
}

ClientRequest parse_client_message(std::string_view text) {
  const json message = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded()) return Rejected{"not valid JSON"};
  if (!message.is_object()) return Rejected{"a client message must be a JSON object"};
  const auto op = message.find("op");
  if (op == message.end() || !op->is_string()) {
    return Rejected{"missing string field \"op\""};
  }
  const std::string name = op->get<std::string>();
  if (name == "subscribe") return parse_subscribe(message);
  if (name == "unsubscribe") return parse_unsubscribe(message);
  return Rejected{"operation \"" + name +
                  "\" is not supported by avs view (capabilities: none; only subscribe and "
                  "unsubscribe)"};
}

ParsedTarget parse_request_target(std::string_view target, const ClientOptions& defaults) {
  ParsedTarget parsed{defaults, ""};
  const std::size_t q = target.find('?');
  if (q == std::string_view::npos) return parsed;
  std::string_view query = target.substr(q + 1);
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
    if (pair.empty()) continue;
    const std::size_t eq = pair.find('=');
    const std::string_view key = pair.substr(0, eq);
    const std::string_view value =
        eq == std::string_view::npos ? std::string_view() : pair.substr(eq + 1);
    if (key != "max_rate_hz") {
      parsed.error = "unknown query parameter \"" + std::string(key) + "\" (known: max_rate_hz)";
      return parsed;
    }
    double rate = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), rate);
    if (ec != std::errc() || end != value.data() + value.size() || !std::isfinite(rate) ||
        rate < 0) {
      parsed.error = "max_rate_hz must be a number >= 0, not \"" + std::string(value) + "\"";
      return parsed;
    }
    parsed.options.max_rate_hz = rate;
  }
  return parsed;
}

}  // namespace avs::view
