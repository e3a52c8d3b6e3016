// Ctrl-C and SIGTERM for the commands that run until they are stopped (bag record/play, topic
// echo/hz/bw, view): the one flag they poll, and the one place that installs the handlers.
// Installed when such a command runs, never when commands are registered, so that every other
// command keeps the default action (end the process).
#pragma once

#include <atomic>

namespace avs::cli {

/// Lowers the flag and routes SIGINT and SIGTERM to it.
void stop_on_interrupt();

/// The flag: raised by SIGINT or SIGTERM after stop_on_interrupt(), or by request_stop().
std::atomic<bool>& stop_requested();

inline void request_stop() { stop_requested() = true; }

}  // namespace avs::cli
