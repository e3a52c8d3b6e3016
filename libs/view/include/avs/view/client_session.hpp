// One connected Foxglove client, without the socket: its subscriptions, what waits to be sent
// to it, and the policy that keeps a slow client from holding anything up. Each subscription
// has a bounded queue; a message that finds it full pushes out the oldest one, which is
// counted as dropped. Image channels can be thinned to the client's max_rate_hz (by receive
// time). Control messages (advertise, status) go first. Not thread-safe: the server adapter
// calls it from its one network thread.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "avs/view/protocol.hpp"

namespace avs::view {

/// Serialised CDR bytes as taken from DDS (encapsulation header included), shared by every
/// client that sends them.
using Payload = std::shared_ptr<const std::vector<std::uint8_t>>;

struct SessionLimits {
  std::size_t queue_depth = 8;            ///< messages waiting per subscription
  std::size_t control_queue_depth = 256;  ///< JSON messages waiting; further statuses dropped
};

/// What to put on the wire next: a JSON text, or a Message Data frame (header + payload).
struct OutgoingMessage {
  bool is_text = false;
  std::string text;
  std::array<std::uint8_t, kMessageDataHeaderSize> header{};
  Payload payload;
  ChannelId channel = 0;
};

struct SubscriptionCounters {
  SubscriptionId id = 0;
  ChannelId channel = 0;
  std::uint64_t offered = 0;    ///< messages of the channel that reached this client
  std::uint64_t sent = 0;       ///< handed to the socket
  std::uint64_t dropped = 0;    ///< pushed out of the full queue (slow client)
  std::uint64_t throttled = 0;  ///< skipped by max_rate_hz
  std::size_t queued = 0;       ///< waiting now
};

class ClientSession {
 public:
  ClientSession(ClientOptions options, SessionLimits limits);

  /// Queues a JSON message (serverInfo, advertise, ...); never dropped.
  void queue_text(std::string json);

  /// Channels this client started or stopped receiving because of one request.
  struct Changes {
    std::vector<ChannelId> subscribed;
    std::vector<ChannelId> unsubscribed;
  };
  /// Handles one text message from the client. A bad request is rejected with a status
  /// message (level error) naming the reason, and counted; it never throws.
  /// `channel_exists` tells which channel ids are advertised now.
  Changes handle_text(std::string_view text, const std::function<bool(ChannelId)>& channel_exists);
  /// Rejects a message this server cannot take (e.g. a binary one): status + count.
  void reject(std::string_view reason);

  /// A message of `channel` received at `receive_ns`: queued for the subscription, if any.
  void offer(ChannelId channel, bool is_image, std::uint64_t receive_ns, const Payload& payload);
  /// The channel is gone (unadvertised): its subscription ends without a word. Returns true
  /// when this client had one.
  bool remove_channel(ChannelId channel);

  /// The next message to send, or nullopt when nothing waits.
  std::optional<OutgoingMessage> next();

  std::vector<ChannelId> subscribed_channels() const;
  std::vector<SubscriptionCounters> counters() const;
  std::uint64_t dropped_total() const { return dropped_total_; }
  std::uint64_t sent_total() const { return sent_total_; }
  std::uint64_t rejected_requests() const { return rejected_; }
  /// The reason of the last rejected request ("" if none).
  const std::string& last_rejection() const { return last_rejection_; }
  const ClientOptions& options() const { return options_; }

 private:
  struct Queued {
    std::uint64_t receive_ns = 0;
    Payload payload;
  };
  struct Subscription {
    SubscriptionCounters counters;
    std::deque<Queued> queue;
    std::optional<std::uint64_t> last_accepted_ns;
  };
  void queue_status(StatusLevel level, std::string message);

  ClientOptions options_;
  SessionLimits limits_;
  std::deque<std::string> control_;
  std::map<ChannelId, Subscription> by_channel_;
  std::map<SubscriptionId, ChannelId> channel_of_;
  ChannelId next_channel_ = 0;  ///< round-robin position among subscriptions
  std::uint64_t dropped_total_ = 0, sent_total_ = 0, rejected_ = 0;
  std::string last_rejection_;
};

}  // namespace avs::view
