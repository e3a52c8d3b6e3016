#include "avs/servo/amplifier_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/select.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace avs::servo {
namespace {

std::uint16_t be16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

struct WriteRequest {
  bool has_write = false;
  std::uint16_t address = 0;
  std::vector<std::uint16_t> values;
};

// Extracts the registers a request writes (0x06, 0x10, 0x17); the PDU starts at `pdu`.
WriteRequest parse_write(const std::uint8_t* pdu, int pdu_length) {
  WriteRequest w;
  const std::uint8_t function = pdu[0];
  auto take = [&](int offset, int count) {
    if (offset + 2 * count > pdu_length || count <= 0) return;
    w.has_write = true;
    for (int i = 0; i < count; ++i) w.values.push_back(be16(pdu + offset + 2 * i));
  };
  if (function == MODBUS_FC_WRITE_SINGLE_REGISTER && pdu_length >= 5) {
    w.address = be16(pdu + 1);
    take(3, 1);
  } else if (function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS && pdu_length >= 6) {
    w.address = be16(pdu + 1);
    take(6, be16(pdu + 3));
  } else if (function == MODBUS_FC_WRITE_AND_READ_REGISTERS && pdu_length >= 10) {
    w.address = be16(pdu + 5);
    take(10, be16(pdu + 7));
  }
  return w;
}

}  // namespace

AmplifierServer::AmplifierServer(AmplifierServerConfig config) : config_(std::move(config)) {
  if (config_.axes.empty()) throw ConfigError("AmplifierServer: no axes configured");
  for (const SimulatedDriveConfig& axis : config_.axes) {
    drives_.push_back(std::make_unique<SimulatedDrive>(axis));
    const int registers = drives_.back()->registers().register_count();
    ModbusMapping mapping(modbus_mapping_new(0, 0, registers, 0));
    if (!mapping) throw ModbusError("modbus_mapping_new: " + std::string(modbus_strerror(errno)));
    drives_.back()->fill_registers({mapping->tab_registers, static_cast<std::size_t>(registers)});
    mappings_.push_back(std::move(mapping));
  }
  ctx_ = make_tcp_context(config_.bind_address, config_.port);
  const int fd = modbus_tcp_listen(ctx_.get(), 4);
  if (fd == -1) {
    throw ModbusError("amplifier server: listen on " + config_.bind_address + ":" +
                      std::to_string(config_.port) + ": " + modbus_strerror(errno));
  }
  listen_socket_ = Socket(fd);
  sockaddr_in address{};
  socklen_t length = sizeof address;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    throw ModbusError("amplifier server: getsockname: " + std::string(std::strerror(errno)));
  }
  port_ = ntohs(address.sin_port);
  io_thread_ = std::thread([this] { io_loop(); });
  if (config_.clock == ClockMode::own_thread) step_thread_ = std::thread([this] { step_loop(); });
}

AmplifierServer::~AmplifierServer() {
  stop_ = true;
  if (step_thread_.joinable()) step_thread_.join();
  if (io_thread_.joinable()) io_thread_.join();
  // modbus_close in the context deleter closes ctx->s, which the I/O loop pointed at a client
  // socket that Socket already closed: detach it first.
  modbus_set_socket(ctx_.get(), -1);
}

void AmplifierServer::step(double dt_s) {
  if (config_.clock != ClockMode::external) {
    throw std::logic_error("AmplifierServer::step: the server runs its own clock");
  }
  std::lock_guard lock(mutex_);
  for (auto& drive : drives_) drive->step(dt_s);
}

void AmplifierServer::step_loop() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(config_.step_period_s));
  auto next = Clock::now() + period;
  while (!stop_) {
    std::this_thread::sleep_until(next);
    {
      std::lock_guard lock(mutex_);
      for (auto& drive : drives_) drive->step(config_.step_period_s);
    }
    next += period;
    const auto now = Clock::now();
    if (now > next + 10 * period) next = now + period;  // do not try to catch up after a stall
  }
}

void AmplifierServer::with_drive(std::size_t axis, const std::function<void(SimulatedDrive&)>& fn) {
  std::lock_guard lock(mutex_);
  fn(*drives_.at(axis));
}

ServerCounters AmplifierServer::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void AmplifierServer::delay_next_replies(int count, double seconds) {
  next_replies_delay_s_ = seconds;
  delayed_replies_left_ = count;
}

void AmplifierServer::set_reply_delay(double seconds) {
  reply_delay_s_ = seconds;
}
void AmplifierServer::drop_connections() {
  drop_requested_ = true;
}
void AmplifierServer::set_silent(bool silent) {
  silent_ = silent;
}
void AmplifierServer::set_stalled(bool stalled) {
  stalled_ = stalled;
}

void AmplifierServer::raise_drive_fault(std::size_t axis, std::uint16_t error_code,
                                        bool latched_only) {
  std::lock_guard lock(mutex_);
  drives_.at(axis)->raise_fault(error_code, latched_only);
}

SimulatedDrive* AmplifierServer::drive_for_unit(int unit_id) {
  for (auto& drive : drives_) {
    if (drive->config().unit_id == unit_id) return drive.get();
  }
  return nullptr;
}

void AmplifierServer::io_loop() {
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  while (!stop_) {
    if (drop_requested_.exchange(false)) clients_.clear();
    fd_set readable;
    FD_ZERO(&readable);
    int max_fd = listen_socket_.get();
    FD_SET(listen_socket_.get(), &readable);
    if (!stalled_) {
      for (const Socket& c : clients_) {
        FD_SET(c.get(), &readable);
        max_fd = std::max(max_fd, c.get());
      }
    }
    timeval timeout{0, 2000};  // wake up regularly to notice stop_ and injections
    const int ready = ::select(max_fd + 1, &readable, nullptr, nullptr, &timeout);
    if (ready <= 0) continue;
    if (FD_ISSET(listen_socket_.get(), &readable)) {
      const int fd = ::accept(listen_socket_.get(), nullptr, nullptr);
      if (fd >= 0) {
        // Each reply goes out at once, as a drive's Modbus TCP server sends it: with Nagle's
        // algorithm a reply right after a late one waited for the client's delayed ACK
        // (about 40 ms), so one late reply made the next late too.
        const int one = 1;
        (void)::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        clients_.emplace_back(fd);
        std::lock_guard lock(mutex_);
        ++counters_.connections_accepted;
      }
    }
    if (stalled_) continue;
    for (std::size_t i = 0; i < clients_.size();) {
      if (!FD_ISSET(clients_[i].get(), &readable)) {
        ++i;
        continue;
      }
      modbus_set_socket(ctx_.get(), clients_[i].get());
      const int length = modbus_receive(ctx_.get(), query);
      if (length == -1) {  // peer closed or broken frame: drop this connection
        clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(i));
        continue;
      }
      if (length > 0) handle_request(query, length);
      ++i;
    }
    modbus_set_socket(ctx_.get(), -1);
  }
}

void AmplifierServer::handle_request(const std::uint8_t* query, int length) {
  const int header = modbus_get_header_length(ctx_.get());
  const int unit_id = query[header - 1];
  {
    std::lock_guard lock(mutex_);
    ++counters_.requests;
  }
  if (silent_) {
    std::lock_guard lock(mutex_);
    ++counters_.dropped_requests;
    return;
  }
  double delay = reply_delay_s_;
  if (delayed_replies_left_ > 0) {
    --delayed_replies_left_;
    delay += next_replies_delay_s_;
  }
  if (delay > 0) std::this_thread::sleep_for(std::chrono::duration<double>(delay));

  std::unique_lock lock(mutex_);
  SimulatedDrive* drive = drive_for_unit(unit_id);
  if (drive == nullptr) {
    ++counters_.exceptions;
    lock.unlock();
    modbus_reply_exception(ctx_.get(), query, MODBUS_EXCEPTION_GATEWAY_TARGET);
    return;
  }
  const auto axis =
      static_cast<std::size_t>(std::find_if(drives_.begin(), drives_.end(),
                                            [&](const auto& d) { return d.get() == drive; }) -
                               drives_.begin());
  modbus_mapping_t* mapping = mappings_[axis].get();
  const WriteRequest write = parse_write(query + header, length - header);
  if (write.has_write) {
    const bool in_map =
        write.address + write.values.size() <= static_cast<std::size_t>(mapping->nb_registers);
    if (in_map && !drive->accepts_write(write.address, write.values.size())) {
      ++counters_.exceptions;
      lock.unlock();
      modbus_reply_exception(ctx_.get(), query, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
      return;
    }
    // Out-of-map writes are left to modbus_reply, which answers with the address exception.
    if (in_map) drive->apply_write(write.address, write.values);
  }
  drive->fill_registers({mapping->tab_registers, static_cast<std::size_t>(mapping->nb_registers)});
  const int rc = modbus_reply(ctx_.get(), query, length, mapping);
  if (rc != -1) ++counters_.replies;
}

}  // namespace avs::servo
