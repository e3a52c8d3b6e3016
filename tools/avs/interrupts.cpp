#include "interrupts.hpp"

#include <csignal>

namespace avs::cli {
namespace {

std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "raised from a signal handler");

void raise_stop(int) { g_stop_requested = true; }

}  // namespace

void stop_on_interrupt() {
  g_stop_requested = false;
  struct sigaction sa {};
  sa.sa_handler = raise_stop;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

std::atomic<bool>& stop_requested() { return g_stop_requested; }

}  // namespace avs::cli
