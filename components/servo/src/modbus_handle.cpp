#include "avs/servo/modbus_handle.hpp"

#include <unistd.h>
#include <cerrno>
#include <cmath>

namespace avs::servo {

void ModbusContextDeleter::operator()(modbus_t* ctx) const noexcept {
  modbus_close(ctx);
  modbus_free(ctx);
}

Socket& Socket::operator=(Socket&& other) noexcept {
  if (this != &other) {
    reset();
    fd_ = other.release();
  }
  return *this;
}

void Socket::reset() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

int check_modbus(int rc, std::string_view what) {
  if (rc == -1) {
    const int err = errno;
    throw ModbusError(std::string(what) + ": " + modbus_strerror(err));
  }
  return rc;
}

ModbusContext make_tcp_context(const std::string& host, int port) {
  ModbusContext ctx(modbus_new_tcp(host.c_str(), port));
  if (!ctx) {
    throw ModbusError("modbus_new_tcp(" + host + ":" + std::to_string(port) +
                      "): " + modbus_strerror(errno));
  }
  return ctx;
}

ModbusContext make_rtu_context(const std::string& device, int baud, char parity, int data_bits,
                               int stop_bits) {
  ModbusContext ctx(modbus_new_rtu(device.c_str(), baud, parity, data_bits, stop_bits));
  if (!ctx) {
    throw ModbusError("modbus_new_rtu(" + device + ", " + std::to_string(baud) +
                      "): " + modbus_strerror(errno));
  }
  return ctx;
}

void set_response_timeout(modbus_t* ctx, double seconds) {
  const double whole = std::floor(seconds);
  auto sec = static_cast<std::uint32_t>(whole);
  auto usec = static_cast<std::uint32_t>(std::lround((seconds - whole) * 1e6));
  if (usec >= 1000000u) {
    ++sec;
    usec = 0;
  }
  check_modbus(modbus_set_response_timeout(ctx, sec, usec), "modbus_set_response_timeout");
}

}  // namespace avs::servo
