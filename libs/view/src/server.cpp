// The network side of `avs view`: Boost.Beast (HTTP + WebSocket over Boost.Asio), one
// io_context on one thread. Everything that touches a session runs on that thread; the
// public calls post to it.
#include "avs/view/server.hpp"

#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

namespace avs::view {

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

/// At most one line per second for each kind of complaint, with the count of the others.
class RateLimitedLog {
 public:
  void log(const std::string& line) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::seconds(1)) {
      ++suppressed_;
      return;
    }
    if (suppressed_ > 0) {
      std::fprintf(stderr, "avs view: (%llu similar messages suppressed)\n",
                   static_cast<unsigned long long>(suppressed_));
    }
    std::fprintf(stderr, "avs view: %s\n", line.c_str());
    last_ = now;
    suppressed_ = 0;
  }

 private:
  std::chrono::steady_clock::time_point last_{};
  std::uint64_t suppressed_ = 0;
};

/// True when the comma-separated Sec-WebSocket-Protocol list offers `wanted`.
bool offers_subprotocol(std::string_view list, std::string_view wanted) {
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    std::string_view item = list.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item == wanted) return true;
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
  return false;
}

std::string no_page(const std::string& why) {
  return "<!doctype html><html><head><meta charset=\"utf-8\"><title>avs view</title></head>"
         "<body><h1>avs view</h1><p><b>NO PAGE:</b> " +
         why +
         "</p><p>The Foxglove WebSocket server runs on this port: open Foxglove and connect to "
         "<code>ws://HOST:PORT</code> (docs/view.md).</p></body></html>";
}

/// Content type by file name ending; nullptr for files the server does not hand out.
const char* content_type(const std::string& name) {
  const auto ends = [&](std::string_view end) {
    return name.size() >= end.size() &&
           name.compare(name.size() - end.size(), end.size(), end) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".png")) return "image/png";
  if (ends(".map") || ends(".json")) return "application/json";
  return nullptr;
}

/// A file name in the page folder: letters, digits, '.', '_', '-', not starting with '.'.
bool plain_file_name(std::string_view name) {
  if (name.empty() || name.front() == '.') return false;
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') {
      return false;
    }
  }
  return true;
}

}  // namespace

class WsSession;

struct Server::Impl {
  ServerOptions options;
  SubscriptionListener listener;
  asio::io_context io{1};
  std::optional<asio::executor_work_guard<asio::io_context::executor_type>> work;
  tcp::acceptor acceptor{io};
  std::thread thread;
  std::uint16_t bound_port = 0;
  std::string session_id;

  // Network thread only.
  std::map<ChannelId, Channel> channels;
  std::map<ChannelId, int> subscribers;  ///< clients subscribed, per channel
  std::set<std::shared_ptr<WsSession>> sessions;
  std::uint64_t next_client_id = 1;
  std::uint64_t clients_total = 0;
  std::uint64_t rejected_closed = 0;  ///< rejections of clients that have gone
  RateLimitedLog rejection_log;

  std::atomic<std::size_t> pending{0};
  std::atomic<std::uint64_t> overload_dropped{0};

  void accept();
  void add_subscriber(ChannelId channel) {
    if (subscribers[channel]++ == 0 && listener) listener(channel, true);
  }
  void remove_subscriber(ChannelId channel) {
    auto it = subscribers.find(channel);
    if (it == subscribers.end()) return;
    if (--it->second <= 0) {
      subscribers.erase(it);
      if (listener) listener(channel, false);
    }
  }
  std::string advertise_all() const {
    std::vector<Channel> list;
    for (const auto& [id, c] : channels) list.push_back(c);
    return advertise_json(list);
  }
};

/// One WebSocket client.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, Server::Impl& server, ClientOptions options)
      : ws_(std::move(socket)), server_(server), session_(options, server.options.limits) {
    beast::error_code ec;
    const auto endpoint = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    if (!ec) remote_ = endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
  }

  void run(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& response) {
      response.set(http::field::server, "avs view");
      response.set(http::field::sec_websocket_protocol, std::string(kSubprotocol));
    }));
    ws_.read_message_max(1u << 20);  // client requests are small JSON texts
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->on_open();
    });
  }

  void offer(ChannelId channel, bool is_image, std::uint64_t receive_ns, const Payload& payload) {
    session_.offer(channel, is_image, receive_ns, payload);
    pump();
  }
  void queue_text(std::string text) {
    session_.queue_text(std::move(text));
    pump();
  }
  bool remove_channel(ChannelId channel) { return session_.remove_channel(channel); }

  ClientStats stats() const {
    ClientStats s;
    s.id = id_;
    s.remote = remote_;
    s.max_rate_hz = session_.options().max_rate_hz;
    s.sent = session_.sent_total();
    s.dropped = session_.dropped_total();
    s.rejected = session_.rejected_requests();
    s.last_rejection = session_.last_rejection();
    s.subscriptions = session_.counters();
    return s;
  }

 private:
  void on_open() {
    id_ = server_.next_client_id++;
    ++server_.clients_total;
    open_ = true;
    server_.sessions.insert(shared_from_this());
    std::fprintf(stderr, "avs view: client %llu connected from %s (max_rate_hz %g)\n",
                 static_cast<unsigned long long>(id_), remote_.c_str(),
                 session_.options().max_rate_hz);
    session_.queue_text(server_info_json(server_.options.name, server_.session_id));
    session_.queue_text(server_.advertise_all());  // at least one advertise, even if empty
    read();
    pump();
  }

  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

  void on_read(beast::error_code ec) {
    if (ec) {
      close();
      return;
    }
    const std::uint64_t rejected_before = session_.rejected_requests();
    if (ws_.got_text()) {
      const std::string text = beast::buffers_to_string(buffer_.data());
      const auto changes = session_.handle_text(
          text, [this](ChannelId id) { return server_.channels.count(id) != 0; });
      for (ChannelId c : changes.subscribed) server_.add_subscriber(c);
      for (ChannelId c : changes.unsubscribed) server_.remove_subscriber(c);
    } else {
      session_.reject("binary client messages are not supported (no clientPublish capability)");
    }
    if (session_.rejected_requests() != rejected_before) {
      server_.rejection_log.log("client " + std::to_string(id_) + " (" + remote_ +
                                "): rejected a request: " + session_.last_rejection());
    }
    buffer_.consume(buffer_.size());
    pump();
    read();
  }

  void pump() {
    if (writing_ || !open_) return;
    auto next = session_.next();
    if (!next) return;
    in_flight_ = std::move(*next);
    writing_ = true;
    auto done = [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      self->in_flight_ = OutgoingMessage{};
      if (ec) {
        self->close();
        return;
      }
      self->pump();
    };
    ws_.text(in_flight_.is_text);
    if (in_flight_.is_text) {
      ws_.async_write(asio::buffer(in_flight_.text), std::move(done));
    } else {
      const std::array<asio::const_buffer, 2> frame = {
          asio::buffer(in_flight_.header),
          asio::buffer(in_flight_.payload->data(), in_flight_.payload->size())};
      ws_.async_write(frame, std::move(done));
    }
  }

  void close() {
    if (!open_) return;
    open_ = false;
    for (ChannelId c : session_.subscribed_channels()) server_.remove_subscriber(c);
    server_.rejected_closed += session_.rejected_requests();
    std::fprintf(stderr,
                 "avs view: client %llu (%s) disconnected: %llu messages sent, %llu dropped\n",
                 static_cast<unsigned long long>(id_), remote_.c_str(),
                 static_cast<unsigned long long>(session_.sent_total()),
                 static_cast<unsigned long long>(session_.dropped_total()));
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().close(ignored);
    server_.sessions.erase(shared_from_this());
  }

  websocket::stream<beast::tcp_stream> ws_;
  Server::Impl& server_;
  ClientSession session_;
  beast::flat_buffer buffer_;
  OutgoingMessage in_flight_;
  bool writing_ = false;
  bool open_ = false;
  std::uint64_t id_ = 0;
  std::string remote_ = "?";
};

/// One HTTP connection: a WebSocket upgrade goes to a WsSession; anything else is answered
/// (the page at `/`) and closed.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Server::Impl& server)
      : stream_(std::move(socket)), server_(server) {}

  void run() {
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, request_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       if (!ec) self->on_request();
                     });
  }

 private:
  void on_request() {
    if (websocket::is_upgrade(request_)) {
      const auto target =
          parse_request_target(std::string_view(request_.target().data(), request_.target().size()),
                               server_.options.client_defaults);
      const auto offered = request_[http::field::sec_websocket_protocol];
      std::string refusal = target.error;
      if (refusal.empty() &&
          !offers_subprotocol(std::string_view(offered.data(), offered.size()), kSubprotocol)) {
        refusal = "the client must offer the WebSocket subprotocol " + std::string(kSubprotocol);
      }
      if (refusal.empty()) {
        stream_.expires_never();
        std::make_shared<WsSession>(stream_.release_socket(), server_, target.options)
            ->run(std::move(request_));
        return;
      }
      server_.rejection_log.log("refused a WebSocket client: " + refusal);
      respond(http::status::bad_request, "text/plain", "avs view: " + refusal + "\n");
      return;
    }
    if (request_.method() != http::verb::get && request_.method() != http::verb::head) {
      respond(http::status::method_not_allowed, "text/plain", "avs view: GET only\n");
    } else {
      serve_file(std::string(request_.target()));
    }
  }

  void serve_file(std::string target) {
    target = target.substr(0, target.find('?'));
    const std::string name = target == "/" ? "index.html" : target.substr(1);
    const std::filesystem::path& root = server_.options.web_root;
    const char* type = content_type(name);
    if (root.empty() || !std::filesystem::is_regular_file(root / "index.html")) {
      if (name == "index.html") {
        respond(http::status::ok, "text/html; charset=utf-8",
                no_page(root.empty() ? "this build has no page (it needs node and npm at build "
                                       "time: bash tools/run.sh test installs them)"
                                     : "no index.html in " + root.string()));
        return;
      }
    } else if (plain_file_name(name) && type != nullptr) {
      std::ifstream in(root / name, std::ios::binary);
      if (in) {
        std::ostringstream body;
        body << in.rdbuf();
        respond(http::status::ok, type, body.str());
        return;
      }
    }
    respond(http::status::not_found, "text/plain", "avs view: no such page: " + target + "\n");
  }

  void respond(http::status status, const char* type, std::string body) {
    auto response = std::make_shared<http::response<http::string_body>>(status, request_.version());
    response->set(http::field::server, "avs view");
    response->set(http::field::content_type, type);
    response->keep_alive(false);
    response->body() = std::move(body);
    response->prepare_payload();
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code, std::size_t) {
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                      });
  }

  beast::tcp_stream stream_;
  Server::Impl& server_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> request_;
};

void Server::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) std::make_shared<HttpSession>(std::move(socket), *this)->run();
    accept();
  });
}

Server::Server(ServerOptions options, SubscriptionListener listener)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->listener = std::move(listener);
  impl_->session_id = std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                         std::chrono::system_clock::now().time_since_epoch())
                                         .count());
}

Server::~Server() {
  stop();
}

void Server::start() {
  Impl& m = *impl_;
  const std::string where = m.options.address + ":" + std::to_string(m.options.port);
  beast::error_code ec;
  const auto address = asio::ip::make_address(m.options.address, ec);
  if (ec)
    throw std::runtime_error("avs view: bad address " + m.options.address + ": " + ec.message());
  const tcp::endpoint endpoint(address, m.options.port);
  m.acceptor.open(endpoint.protocol(), ec);
  if (!ec) m.acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) m.acceptor.bind(endpoint, ec);
  if (!ec) m.acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("avs view: cannot listen on " + where + ": " + ec.message());
  m.bound_port = m.acceptor.local_endpoint().port();
  m.work.emplace(m.io.get_executor());
  m.accept();
  m.thread = std::thread([&m] { m.io.run(); });
}

void Server::stop() {
  Impl& m = *impl_;
  if (!m.thread.joinable()) return;
  asio::post(m.io, [&m] {
    beast::error_code ignored;
    m.acceptor.close(ignored);
    m.sessions.clear();
  });
  m.work.reset();
  m.io.stop();
  m.thread.join();
}

std::uint16_t Server::port() const {
  return impl_->bound_port;
}

void Server::advertise(Channel channel) {
  asio::post(impl_->io, [&m = *impl_, channel = std::move(channel)]() mutable {
    const ChannelId id = channel.id;
    const std::string text = advertise_json(std::span<const Channel>(&channel, 1));
    m.channels[id] = std::move(channel);
    for (const auto& s : m.sessions) s->queue_text(text);
  });
}

void Server::unadvertise(ChannelId channel) {
  asio::post(impl_->io, [&m = *impl_, channel] {
    if (m.channels.erase(channel) == 0) return;
    const std::string text = unadvertise_json(std::span<const ChannelId>(&channel, 1));
    for (const auto& s : m.sessions) {
      if (s->remove_channel(channel)) m.remove_subscriber(channel);
      s->queue_text(text);
    }
  });
}

void Server::publish(ChannelId channel, std::uint64_t receive_ns, Payload payload) {
  Impl& m = *impl_;
  if (m.pending.fetch_add(1, std::memory_order_relaxed) >= m.options.max_pending_messages) {
    m.pending.fetch_sub(1, std::memory_order_relaxed);
    m.overload_dropped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  asio::post(m.io, [&m, channel, receive_ns, payload = std::move(payload)] {
    m.pending.fetch_sub(1, std::memory_order_relaxed);
    const auto it = m.channels.find(channel);
    if (it == m.channels.end()) return;
    const bool is_image = it->second.is_image;
    // Copy the set: a failed write inside offer() may close (erase) a session.
    const std::vector<std::shared_ptr<WsSession>> sessions(m.sessions.begin(), m.sessions.end());
    for (const auto& s : sessions) s->offer(channel, is_image, receive_ns, payload);
  });
}

ServerStats Server::stats() const {
  Impl& m = *impl_;
  if (!m.thread.joinable()) return {};
  auto promise = std::make_shared<std::promise<ServerStats>>();
  auto future = promise->get_future();
  asio::post(m.io, [&m, promise] {
    ServerStats s;
    s.valid = true;
    s.clients_total = m.clients_total;
    s.overload_dropped = m.overload_dropped.load();
    s.rejected_total = m.rejected_closed;
    for (const auto& session : m.sessions) {
      s.clients.push_back(session->stats());
      s.rejected_total += s.clients.back().rejected;
    }
    for (const auto& [id, c] : m.channels) {
      Channel copy = c;
      copy.schema.clear();
      s.channels.push_back(std::move(copy));
    }
    promise->set_value(std::move(s));
  });
  if (future.wait_for(std::chrono::seconds(2)) != std::future_status::ready) return {};
  return future.get();
}

}  // namespace avs::view
