#include "avs/view/client_session.hpp"

#include <type_traits>

namespace avs::view {

ClientSession::ClientSession(ClientOptions options, SessionLimits limits)
    : options_(options), limits_(limits) {
  if (limits_.queue_depth == 0) limits_.queue_depth = 1;
}

void ClientSession::queue_text(std::string json) {
  control_.push_back(std::move(json));
}

void ClientSession::queue_status(StatusLevel level, std::string message) {
  // A client that floods us with bad requests and reads nothing must not grow this queue.
  if (control_.size() >= limits_.control_queue_depth) return;
  control_.push_back(status_json(level, message));
}

void ClientSession::reject(std::string_view reason) {
  ++rejected_;
  last_rejection_ = std::string(reason);
  queue_status(StatusLevel::error, "avs view rejected a request: " + std::string(reason));
}

ClientSession::Changes ClientSession::handle_text(
    std::string_view text, const std::function<bool(ChannelId)>& channel_exists) {
  Changes changes;
  const ClientRequest request = parse_client_message(text);
  if (const auto* r = std::get_if<Rejected>(&request)) {
    reject(r->reason);
    return changes;
  }
  if (const auto* s = std::get_if<Subscribe>(&request)) {
    for (const Subscribe::Item& item : s->subscriptions) {
      if (channel_of_.count(item.id) != 0) {
        reject("subscribe: subscription id " + std::to_string(item.id) + " is already in use");
      } else if (!channel_exists(item.channel)) {
        reject("subscribe: channel " + std::to_string(item.channel) + " is not advertised");
      } else if (by_channel_.count(item.channel) != 0) {
        reject("subscribe: channel " + std::to_string(item.channel) + " already has subscription " +
               std::to_string(by_channel_.at(item.channel).counters.id) +
               " (one per channel and client)");
      } else {
        Subscription& sub = by_channel_[item.channel];
        sub.counters.id = item.id;
        sub.counters.channel = item.channel;
        channel_of_[item.id] = item.channel;
        changes.subscribed.push_back(item.channel);
      }
    }
    return changes;
  }
  for (const SubscriptionId id : std::get<Unsubscribe>(request).ids) {
    const auto it = channel_of_.find(id);
    if (it == channel_of_.end()) {
      reject("unsubscribe: no subscription " + std::to_string(id));
      continue;
    }
    changes.unsubscribed.push_back(it->second);
    by_channel_.erase(it->second);
    channel_of_.erase(it);
  }
  return changes;
}

void ClientSession::offer(ChannelId channel, bool is_image, std::uint64_t receive_ns,
                          const Payload& payload) {
  const auto it = by_channel_.find(channel);
  if (it == by_channel_.end()) return;
  Subscription& sub = it->second;
  ++sub.counters.offered;
  if (is_image && options_.max_rate_hz > 0 && sub.last_accepted_ns) {
    const double min_interval_ns = 1e9 / options_.max_rate_hz;
    if (static_cast<double>(receive_ns - *sub.last_accepted_ns) < min_interval_ns) {
      ++sub.counters.throttled;
      return;
    }
  }
  sub.last_accepted_ns = receive_ns;
  if (sub.queue.size() >= limits_.queue_depth) {
    sub.queue.pop_front();  // the oldest goes: a live view wants the newest
    ++sub.counters.dropped;
    ++dropped_total_;
  }
  sub.queue.push_back({receive_ns, payload});
}

bool ClientSession::remove_channel(ChannelId channel) {
  const auto it = by_channel_.find(channel);
  if (it == by_channel_.end()) return false;
  channel_of_.erase(it->second.counters.id);
  by_channel_.erase(it);
  return true;
}

std::optional<OutgoingMessage> ClientSession::next() {
  if (!control_.empty()) {
    OutgoingMessage m;
    m.is_text = true;
    m.text = std::move(control_.front());
    control_.pop_front();
    return m;
  }
  if (by_channel_.empty()) return std::nullopt;
  // Round robin: the first non-empty queue at or after next_channel_, wrapping around.
  auto start = by_channel_.lower_bound(next_channel_);
  for (std::size_t n = 0; n < by_channel_.size(); ++n) {
    if (start == by_channel_.end()) start = by_channel_.begin();
    Subscription& sub = start->second;
    if (!sub.queue.empty()) {
      OutgoingMessage m;
      m.channel = start->first;
      m.header = message_data_header(sub.counters.id, sub.queue.front().receive_ns);
      m.payload = std::move(sub.queue.front().payload);
      sub.queue.pop_front();
      ++sub.counters.sent;
      ++sent_total_;
      next_channel_ = start->first + 1;
      return m;
    }
    ++start;
  }
  return std::nullopt;
}

std::vector<ChannelId> ClientSession::subscribed_channels() const {
  std::vector<ChannelId> ids;
  for (const auto& [channel, sub] : by_channel_) ids.push_back(channel);
  return ids;
}

std::vector<SubscriptionCounters> ClientSession::counters() const {
  std::vector<SubscriptionCounters> all;
  for (const auto& [channel, sub] : by_channel_) {
    SubscriptionCounters c = sub.counters;
    c.queued = sub.queue.size();
    all.push_back(c);
  }
  return all;
}

}  // namespace avs::view
