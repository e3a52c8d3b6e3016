// The DLPC350 command client over a HidTransport: numbered requests, ACK/NACK and replies
// checked, the sequence configured and validated, start / pause / stop, status read-back.
// Failures throw Dlpc350Error naming the command and what came back.
#pragma once

#include <chrono>
#include <stdexcept>
#include <string>

#include "avs/projector/dlpc350_protocol.hpp"
#include "avs/projector/hid_transport.hpp"
#include "avs/projector/pattern_sequence.hpp"

namespace avs::projector {

class Dlpc350Error : public std::runtime_error {
 public:
  enum class Kind : std::uint8_t {
    kTimeout,       ///< no reply within the USB timeout
    kDisconnected,  ///< the device is gone
    kNack,          ///< the controller refused the command
    kBadReply,      ///< a report that is not the reply asked for
  };
  Dlpc350Error(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

/// The three status bytes and what they say.
struct DeviceStatus {
  std::uint8_t hardware = 0;
  std::uint8_t system = 0;
  std::uint8_t main = 0;
  bool ok() const { return hardware_status_ok(hardware) && (system & 0x01) != 0; }
  bool running() const { return (main & kMainSequencerRunning) != 0; }
  /// "hardware: ...; system: ...; main: ..."
  std::string words() const;
};

class Dlpc350Client {
 public:
  /// `usb_timeout`: how long one reply may take. `match_sequence`: skip replies with another
  /// sequence number (late answers to a request that timed out), at most `max_stale_replies`
  /// of them; TI documents the echo for the DLPC900 and its host code numbers DLPC350 writes,
  /// but no DLPC350 document here says the DLPC350 echoes it: false takes any reply.
  Dlpc350Client(HidTransport& transport, std::chrono::milliseconds usb_timeout,
                bool match_sequence = true, int max_stale_replies = 4);

  /// A write the controller acknowledges (throws on NACK, timeout, disconnection).
  void write(Command command, std::vector<std::uint8_t> data);
  /// A read: the reply's data, at least `min_bytes` of it.
  std::vector<std::uint8_t> read(Command command, std::size_t min_bytes);

  DeviceStatus read_status();
  /// Sends configure_requests(config), then reads the validation until it is not busy
  /// (at most `max_polls` reads). Does not start the sequence.
  Validation configure(const SequenceConfig& config, int max_polls);
  void start() { write(Command::kPatternStartStop, {2}); }
  void pause() { write(Command::kPatternStartStop, {1}); }
  void stop() { write(Command::kPatternStartStop, {0}); }

 private:
  Reply transact(Request request);

  HidTransport& transport_;
  std::chrono::milliseconds usb_timeout_;
  bool match_sequence_;
  int max_stale_replies_;
  std::uint8_t next_sequence_ = 0;
};

}  // namespace avs::projector
