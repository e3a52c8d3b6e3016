#include "avs/runtime/logger.hpp"
#include "avs/runtime/log_clock.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

namespace avs::runtime {

std::string log_clock_text(std::chrono::system_clock::time_point when) {
  const auto secs = std::chrono::system_clock::to_time_t(when);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(when.time_since_epoch()).count() % 1000;
  std::tm tm{};
  localtime_r(&secs, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%H:%M:%S", &tm);
  char text[40];
  std::snprintf(text, sizeof text, "%s.%03lld", stamp, static_cast<long long>(ms));
  return text;
}

void Logger::write(LogLevel level, const std::string& text) const {
  static constexpr const char* kNames[] = {"DEBUG", "INFO", "WARN", "ERROR"};
  const std::string stamp = log_clock_text(std::chrono::system_clock::now());
  // One fprintf per line so lines from several threads do not interleave.
  std::fprintf(stderr, "[%s] [%s] [%s] %s\n", stamp.c_str(), kNames[static_cast<int>(level)],
               name_.c_str(), text.c_str());
}

}  // namespace avs::runtime
