#include "avs/runtime/logger.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

namespace avs::runtime {

void Logger::write(LogLevel level, const std::string& text) const {
  static constexpr const char* kNames[] = {"DEBUG", "INFO", "WARN", "ERROR"};
  const auto now = std::chrono::system_clock::now();
  const auto secs = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  localtime_r(&secs, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%H:%M:%S", &tm);
  // One fprintf per line so lines from several threads do not interleave.
  std::fprintf(stderr, "[%s.%03lld] [%s] [%s] %s\n", stamp, static_cast<long long>(ms),
               kNames[static_cast<int>(level)], name_.c_str(), text.c_str());
}

}  // namespace avs::runtime
