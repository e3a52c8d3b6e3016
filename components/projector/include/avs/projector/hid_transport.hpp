// The one thing the DLPC350 client needs of USB: write a 64-byte HID report, read one with a
// timeout. hidapi (src/hidapi_transport.cpp) and the emulator (dlpc350_emulator.hpp) implement it.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "avs/projector/dlpc350_protocol.hpp"

namespace avs::projector {

enum class IoResult : std::uint8_t {
  kOk,
  kTimeout,       ///< no report within the timeout (the device is there but silent)
  kDisconnected,  ///< the handle is dead (unplugged, powered off): open a new one
};

/// An open HID device. Not thread-safe: one client uses it.
class HidTransport {
 public:
  virtual ~HidTransport() = default;
  virtual IoResult write(const Report& report) = 0;
  virtual IoResult read(Report& report, std::chrono::milliseconds timeout) = 0;
  /// "hidapi 0451:6401 /dev/hidraw3 serial ..." for the log.
  virtual std::string description() const = 0;
};

/// Opens the device: a transport, or nullptr with `why_not` set (no such device, no access).
using TransportOpener = std::function<std::unique_ptr<HidTransport>(std::string& why_not)>;

}  // namespace avs::projector
