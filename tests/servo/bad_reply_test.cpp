// Issue 20 1.5: Modbus TCP replies with a wrong MBAP unit id or a length of 0xFFFF were
// accepted. A proxy on 127.0.0.1 between the drive client and the simulated amplifier
// corrupts one cyclic (0x17) reply on request; the client must reject it (link fault, torque
// 0, counted), never throw, and recover through its reconnect. The reads and writes of the
// connection's configuration are checked the same way: a corrupted one fails the connect.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <thread>
#include <vector>

#include "avs/servo/amplifier_server.hpp"
#include "avs/servo/drive_client.hpp"

namespace avs::servo {
namespace {

constexpr double exchange_rate_hz = 20.0;
constexpr double exchange_period_s = 1.0 / exchange_rate_hz;

enum class Corruption : int {
  none,
  wrong_unit_id,       ///< MBAP unit id of the other axis
  length_ffff,         ///< MBAP length field 0xFFFF
  short_byte_count,    ///< 0x17 byte count (and the frame) one register short
  wrong_function_code  ///< a 0x03 reply to a 0x17 or 0x10 request, 0x04 to a 0x03 one
};

bool recv_exact(int fd, std::uint8_t* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::recv(fd, data + done, size - done, 0);
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

bool write_all(int fd, const std::vector<std::uint8_t>& data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::send(fd, data.data() + done, data.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

/// One MBAP frame (7-byte header, then length - 1 bytes), as sent by a well-behaved peer.
bool read_frame(int fd, std::vector<std::uint8_t>& frame) {
  frame.resize(7);
  if (!recv_exact(fd, frame.data(), 7)) return false;
  const std::size_t length = (std::size_t{frame[4]} << 8) | frame[5];
  if (length < 1 || length > 254) return false;
  frame.resize(6 + length);
  return recv_exact(fd, frame.data() + 7, length - 1);
}

/// Forwards whole MBAP frames between one client at a time and the amplifier server, and
/// corrupts the next 0x17 reply when asked.
class CorruptingProxy {
 public:
  explicit CorruptingProxy(int upstream_port) : upstream_port_(upstream_port) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listen_fd_, 4) != 0) {
      throw std::runtime_error("proxy: cannot listen on 127.0.0.1");
    }
    socklen_t len = sizeof addr;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~CorruptingProxy() {
    stop_ = true;
    thread_.join();
    ::close(listen_fd_);
  }
  CorruptingProxy(const CorruptingProxy&) = delete;
  CorruptingProxy& operator=(const CorruptingProxy&) = delete;

  int port() const { return port_; }
  /// Corrupts the next reply to a request with function code `function` (0x17: the cyclic
  /// write-and-read; 0x03 and 0x10: the configuration's reads and writes).
  void corrupt_next_reply(Corruption c, std::uint8_t function = 0x17) {
    function_.store(function);
    next_.store(static_cast<int>(c));
  }
  int corrupted_replies() const { return corrupted_.load(); }

 private:
  void run() {
    while (!stop_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const int client = ::accept(listen_fd_, nullptr, nullptr);
      if (client < 0) continue;
      const int upstream = connect_upstream();
      if (upstream >= 0) serve(client, upstream);
      ::close(client);
      if (upstream >= 0) ::close(upstream);
    }
  }

  int connect_upstream() const {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(upstream_port_));
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(fd);
      return -1;
    }
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    return fd;
  }

  void serve(int client, int upstream) {
    const int one = 1;
    ::setsockopt(client, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    std::vector<std::uint8_t> request, reply;
    while (!stop_) {
      pollfd p{client, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      if (!read_frame(client, request)) return;  // the client closed (reconnect)
      if (!write_all(upstream, request) || !read_frame(upstream, reply)) return;
      if (request[7] == function_.load()) corrupt(reply);
      if (!write_all(client, reply)) return;
    }
  }

  void corrupt(std::vector<std::uint8_t>& reply) {
    const auto c = static_cast<Corruption>(next_.exchange(static_cast<int>(Corruption::none)));
    switch (c) {
      case Corruption::none:
        return;
      case Corruption::wrong_unit_id:
        reply[6] = reply[6] == 1 ? 2 : 1;
        break;
      case Corruption::length_ffff:
        reply[4] = 0xFF;
        reply[5] = 0xFF;
        break;
      case Corruption::short_byte_count: {
        reply[8] = static_cast<std::uint8_t>(reply[8] - 2);
        reply.resize(reply.size() - 2);
        const std::size_t length = reply.size() - 6;
        reply[4] = static_cast<std::uint8_t>(length >> 8);
        reply[5] = static_cast<std::uint8_t>(length & 0xFF);
        break;
      }
      case Corruption::wrong_function_code:
        reply[7] = reply[7] == 0x03 ? 0x04 : 0x03;
        break;
    }
    ++corrupted_;
  }

  int upstream_port_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> next_{static_cast<int>(Corruption::none)};
  std::atomic<std::uint8_t> function_{0x17};
  std::atomic<int> corrupted_{0};
  std::thread thread_;
};

class BadReplyTest : public ::testing::TestWithParam<Corruption> {
 protected:
  void SetUp() override {
    AmplifierServerConfig server_config;
    for (auto& axis : server_config.axes) axis.watchdog_timeout_s = 0;  // isolate the host side
    server_ = std::make_unique<AmplifierServer>(server_config);
    server_->step(exchange_period_s);
    proxy_ = std::make_unique<CorruptingProxy>(server_->port());
    DriveClientConfig c = default_drive_client_config("127.0.0.1", proxy_->port());
    c.cycle_rate_hz = exchange_rate_hz;
    c.response_timeout_s = 0.02;
    c.command_freshness.timeout_s = 3 * exchange_period_s;
    c.reconnect_backoff_initial_s = exchange_period_s;
    c.reconnect_backoff_max_s = 2 * exchange_period_s;
    client_ = std::make_unique<DriveClient>(c);
    client_->connect();
    client_->activate(t_);
    for (int i = 0; i < 6; ++i) cycle();
  }

  CycleResult cycle() {
    t_ += exchange_period_s;
    client_->set_command({1.0, 0.1}, t_, t_);
    CycleResult r = client_->cycle(t_);
    server_->step(exchange_period_s);
    return r;
  }

  std::unique_ptr<AmplifierServer> server_;
  std::unique_ptr<CorruptingProxy> proxy_;
  std::unique_ptr<DriveClient> client_;
  double t_ = 0;
};

TEST_P(BadReplyTest, IsRejectedCountedAndTheLinkRecovers) {
  ASSERT_TRUE(cycle().link_ok);
  proxy_->corrupt_next_reply(GetParam());
  CycleResult r;
  ASSERT_NO_THROW(r = cycle());  // pan's exchange gets the bad reply
  ASSERT_EQ(proxy_->corrupted_replies(), 1);
  EXPECT_FALSE(r.link_ok);
  EXPECT_TRUE(r.link_fault);
  EXPECT_NE(r.fault_message.find("bad reply"), std::string::npos) << r.fault_message;
  for (const AxisFeedback& a : r.axes) {
    EXPECT_FALSE(a.valid) << "data of a rejected reply was used";
    EXPECT_EQ(a.commanded_torque_nm, 0.0);
  }
  EXPECT_EQ(client_->statistics().bad_replies, 1u);
  bool recovered = false;
  for (int i = 0; i < 20 && !recovered; ++i) recovered = cycle().link_ok;
  EXPECT_TRUE(recovered);
  EXPECT_GE(client_->statistics().reconnects, 1u);
}

TEST_P(BadReplyTest, InAConfigurationReadOrWriteFailsTheConnect) {
  client_.reset();  // the proxy serves one connection at a time
  for (const std::uint8_t function : {std::uint8_t{0x03}, std::uint8_t{0x10}}) {
    SCOPED_TRACE("function " + std::to_string(function));
    DriveClientConfig c = default_drive_client_config("127.0.0.1", proxy_->port());
    c.cycle_rate_hz = exchange_rate_hz;
    c.response_timeout_s = 0.02;
    DriveClient fresh(c);
    const int before = proxy_->corrupted_replies();
    proxy_->corrupt_next_reply(GetParam(), function);
    try {
      fresh.connect();
      ADD_FAILURE() << "connect accepted a corrupted configuration reply";
    } catch (const ModbusError& e) {
      EXPECT_NE(std::string(e.what()).find("bad reply"), std::string::npos) << e.what();
    }
    EXPECT_EQ(proxy_->corrupted_replies(), before + 1);
    EXPECT_NO_THROW(fresh.connect());  // a clean connection is trusted again
  }
}

INSTANTIATE_TEST_SUITE_P(Corruptions, BadReplyTest,
                         ::testing::Values(Corruption::wrong_unit_id, Corruption::length_ffff,
                                           Corruption::short_byte_count,
                                           Corruption::wrong_function_code),
                         [](const ::testing::TestParamInfo<Corruption>& info) {
                           switch (info.param) {
                             case Corruption::wrong_unit_id:
                               return std::string("WrongUnitId");
                             case Corruption::length_ffff:
                               return std::string("LengthFFFF");
                             case Corruption::short_byte_count:
                               return std::string("ShortByteCount");
                             case Corruption::wrong_function_code:
                               return std::string("WrongFunctionCode");
                             default:
                               return std::string("None");
                           }
                         });

}  // namespace
}  // namespace avs::servo
