// What a component does with an input sample it cannot use (wrong size, encoding, index, NaN):
// reject it with a reason, count it for /diagnostics (`rejected_samples`) and log it without
// flooding (the first few, then every 1000th). The graph keeps running; only a broken
// configuration stops start-up.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include "avs/runtime/logger.hpp"

namespace avs::runtime {

class SampleRejections {
 public:
  /// Log lines for the first this many rejections, then for every 1000th.
  static constexpr std::uint64_t kLoggedFirst = 5;
  static constexpr std::uint64_t kLogEvery = 1000;

  /// `input` names what is rejected in the log ("/camera/pattern frame").
  SampleRejections(const Logger& log, std::string input) : log_(log), input_(std::move(input)) {}

  /// Counts one rejected sample and logs `reason` if this one is due.
  void reject(std::string_view reason) {
    const std::uint64_t n = count_.fetch_add(1, std::memory_order_relaxed) + 1;
    if (n <= kLoggedFirst || n % kLogEvery == 0) {
      log_.warn(input_, " rejected (", n, " so far",
                n == kLoggedFirst ? "; logging every 1000th" : "", "): ", reason);
    }
  }

  /// Rejections so far (any thread).
  std::uint64_t count() const { return count_.load(std::memory_order_relaxed); }

  /// The /diagnostics key/value.
  std::pair<std::string, std::string> diagnostic() const {
    return {"rejected_samples", std::to_string(count())};
  }

 private:
  const Logger& log_;
  std::string input_;
  std::atomic<std::uint64_t> count_{0};
};

}  // namespace avs::runtime
