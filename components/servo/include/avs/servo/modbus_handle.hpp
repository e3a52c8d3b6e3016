// RAII for libmodbus contexts, mappings and sockets, and the one helper that checks libmodbus
// return codes and adds context.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include <modbus.h>

namespace avs::servo {

/// Errors from the Modbus adapters, with the operation and peer in the message.
class ModbusError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Configuration rejected at start-up (register map, link budget); one line of explanation.
class ConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct ModbusContextDeleter {
  void operator()(modbus_t* ctx) const noexcept;
};
using ModbusContext = std::unique_ptr<modbus_t, ModbusContextDeleter>;

struct ModbusMappingDeleter {
  void operator()(modbus_mapping_t* mapping) const noexcept { modbus_mapping_free(mapping); }
};
using ModbusMapping = std::unique_ptr<modbus_mapping_t, ModbusMappingDeleter>;

/// An owned file descriptor.
class Socket {
 public:
  Socket() = default;
  explicit Socket(int fd) : fd_(fd) {}
  Socket(Socket&& other) noexcept : fd_(other.release()) {}
  Socket& operator=(Socket&& other) noexcept;
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  ~Socket() { reset(); }
  int get() const { return fd_; }
  int release() noexcept {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void reset() noexcept;

 private:
  int fd_ = -1;
};

/// Throws ModbusError("<what>: <modbus_strerror(errno)>") when rc == -1; returns rc.
int check_modbus(int rc, std::string_view what);

/// Creates a TCP client/server context; throws with the host and port on failure.
ModbusContext make_tcp_context(const std::string& host, int port);
/// Creates an RTU context; throws with the device on failure.
ModbusContext make_rtu_context(const std::string& device, int baud, char parity, int data_bits,
                               int stop_bits);

/// Sets a libmodbus timeout given in seconds.
void set_response_timeout(modbus_t* ctx, double seconds);

}  // namespace avs::servo
