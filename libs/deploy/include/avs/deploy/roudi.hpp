// iceoryx's RouDi daemon for Cyclone DDS shared memory: started before the containers of a
// host with `shared_memory: true` (and by `avs bench transport`), stopped after them.
#pragma once

#include <sys/types.h>

#include <string>

namespace avs::deploy {

class Roudi {
 public:
  /// Starts `iox-roudi` with mempools for 256 KiB images unless a RouDi is already running
  /// (then it is used and left alone). Throws runtime::Error when iox-roudi is missing
  /// (Debian package `iceoryx`) or does not come up within `timeout_s`.
  explicit Roudi(double timeout_s = 10.0);
  ~Roudi();
  Roudi(const Roudi&) = delete;
  Roudi& operator=(const Roudi&) = delete;

  bool started_here() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  /// The RouDi command line or "an already running RouDi".
  const std::string& description() const { return description_; }

  /// Path of iox-roudi on PATH, or "".
  static std::string find_executable();
  /// True when a process named iox-roudi is running.
  static bool running();

 private:
  pid_t pid_ = -1;
  std::string config_dir_;
  std::string description_;
};

}  // namespace avs::deploy
