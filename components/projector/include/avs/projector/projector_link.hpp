// The projector's life over USB, stepped by its owner (the `projector` component's timer; tests
// with made-up times): open the device, configure and validate the sequence, start it, read
// the status back periodically; on a lost device or repeated timeouts close it, report, and
// reopen when it is back (a reopened device is configured again: it may have been power
// cycled). A sequence the controller declares invalid is refused with its status words and
// never started. No threads, no clock of its own.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "avs/projector/dlpc350_client.hpp"
#include "avs/projector/hid_transport.hpp"
#include "avs/projector/pattern_sequence.hpp"

namespace avs::projector {

using SteadyTime = std::chrono::steady_clock::time_point;

struct LinkConfig {
  SequenceConfig sequence;
  std::chrono::milliseconds usb_timeout{200};        ///< one reply
  std::chrono::milliseconds reconnect_period{1000};  ///< between attempts to open the device
  std::chrono::milliseconds status_period{1000};     ///< between status read-backs
  int timeouts_before_lost = 3;  ///< consecutive timeouts after which the device is reopened
  int max_validate_polls = 100;  ///< LUT_VALID reads while the controller is busy
  bool match_reply_sequence = true;  ///< Dlpc350Client's match_sequence
};

enum class LinkState : std::uint8_t {
  kDisconnected,  ///< no device (yet, or lost): reopened every reconnect_period
  kRunning,       ///< sequence validated and started; status read back
  kRefused,       ///< the controller declared the sequence invalid: not started
};
const char* link_state_name(LinkState s);

/// Something the owner logs (levels as the runtime's logger has them).
struct LinkEvent {
  enum class Level : std::uint8_t { kInfo, kWarn, kError } level = Level::kInfo;
  std::string text;
};

struct LinkCounters {
  std::uint64_t connects = 0;  ///< device opened and sequence started
  std::uint64_t connect_failures = 0;
  std::uint64_t disconnects = 0;  ///< device lost while in use
  std::uint64_t timeouts = 0;     ///< USB read timeouts
  std::uint64_t nacks = 0;
  std::uint64_t bad_replies = 0;
  std::uint64_t status_reads = 0;
  std::uint64_t status_faults = 0;  ///< status reads with a hardware or memory fault bit
};

class ProjectorLink {
 public:
  ProjectorLink(LinkConfig config, TransportOpener opener);
  ProjectorLink(const ProjectorLink&) = delete;
  ProjectorLink& operator=(const ProjectorLink&) = delete;
  ~ProjectorLink();  ///< stops the sequence if the device is there (errors ignored)

  /// Does what is due at `now`; returns what to log.
  std::vector<LinkEvent> step(SteadyTime now);
  /// Stops the sequence (best effort) and closes the device.
  std::vector<LinkEvent> close();

  LinkState state() const { return state_; }
  const LinkCounters& counters() const { return counters_; }
  /// The last validation (words), status words and error seen ("" before any).
  const std::string& validation_words() const { return validation_words_; }
  const std::string& status_words() const { return status_words_; }
  const std::string& last_error() const { return last_error_; }
  const std::string& device_description() const { return description_; }

 private:
  void connect(std::vector<LinkEvent>& events);
  void poll_status(std::vector<LinkEvent>& events);
  void on_error(const Dlpc350Error& e, std::vector<LinkEvent>& events);
  void drop_device();

  LinkConfig config_;
  TransportOpener opener_;
  std::unique_ptr<HidTransport> transport_;
  std::unique_ptr<Dlpc350Client> client_;
  LinkState state_ = LinkState::kDisconnected;
  std::optional<SteadyTime> next_attempt_;
  std::optional<SteadyTime> next_status_;
  int consecutive_timeouts_ = 0;
  bool open_failure_reported_ = false;
  LinkCounters counters_;
  std::string validation_words_;
  std::string status_words_;
  std::string last_error_;
  std::string description_;
};

}  // namespace avs::projector
