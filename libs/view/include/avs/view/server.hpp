// The Foxglove WebSocket server of `avs view`: accepts clients on one TCP port (WebSocket
// with subprotocol foxglove.websocket.v1, and plain HTTP for the page at `/`), advertises the
// channels it is given and forwards their messages to the clients that subscribed, through
// each client's ClientSession (bounded queues, drop-oldest). One network thread; every public
// call may come from any thread and never waits for a client. Boost.Beast is used only in
// server.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "avs/view/client_session.hpp"
#include "avs/view/protocol.hpp"

namespace avs::view {

struct ServerOptions {
  std::string address = "127.0.0.1";  ///< "0.0.0.0" to accept clients from other hosts
  std::uint16_t port = 8765;          ///< Foxglove's default; 0 picks a free port
  std::string name = "avs view";      ///< serverInfo name
  ClientOptions client_defaults;      ///< a client's URL query may override them
  SessionLimits limits;
  /// Messages handed to publish() that the network thread has not taken yet; beyond this
  /// they are dropped at once and counted (overload_dropped).
  std::size_t max_pending_messages = 4096;
  /// Folder of the page served at `/` (index.html and the files beside it; no subfolders).
  /// Empty or without index.html: `/` answers with a notice that the page is not available.
  std::filesystem::path web_root;
};

struct ClientStats {
  std::uint64_t id = 0;
  std::string remote;  ///< "127.0.0.1:53412"
  double max_rate_hz = 0;
  std::uint64_t sent = 0, dropped = 0, rejected = 0;
  std::string last_rejection;
  std::vector<SubscriptionCounters> subscriptions;
};

struct ServerStats {
  bool valid = false;  ///< false: the network thread did not answer in time
  std::vector<ClientStats> clients;
  std::vector<Channel> channels;  ///< schema text left empty
  std::uint64_t clients_total = 0;
  std::uint64_t overload_dropped = 0;
  std::uint64_t rejected_total = 0;  ///< client requests rejected, closed clients included
};

class Server {
 public:
  /// Called on the network thread when a channel gets its first subscriber among all clients
  /// (true) or loses its last one (false).
  using SubscriptionListener = std::function<void(ChannelId channel, bool subscribed)>;

  Server(ServerOptions options, SubscriptionListener listener);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Listens and starts the network thread. Throws std::runtime_error naming the address and
  /// the reason when the port cannot be opened.
  void start();
  void stop();
  /// The port listened on (the chosen one when options.port was 0).
  std::uint16_t port() const;

  void advertise(Channel channel);
  void unadvertise(ChannelId channel);
  /// A message of `channel`, received at `receive_ns` (wall clock, ns since the epoch).
  void publish(ChannelId channel, std::uint64_t receive_ns, Payload payload);
  /// A snapshot from the network thread (waits at most 2 s for it).
  ServerStats stats() const;

  /// The network thread's state (server.cpp); opaque, public only so that server.cpp's
  /// session classes can name it.
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace avs::view
