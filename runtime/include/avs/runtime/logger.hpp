// Logging tagged with the component's name, to stderr, one line per message.
#pragma once

#include <sstream>
#include <string>
#include <utility>

namespace avs::runtime {

enum class LogLevel { debug = 0, info = 1, warn = 2, error = 3 };

class Logger {
 public:
  explicit Logger(std::string name, LogLevel level = LogLevel::info)
      : name_(std::move(name)), level_(level) {}

  template <class... Args>
  void debug(Args&&... args) const { log(LogLevel::debug, std::forward<Args>(args)...); }
  template <class... Args>
  void info(Args&&... args) const { log(LogLevel::info, std::forward<Args>(args)...); }
  template <class... Args>
  void warn(Args&&... args) const { log(LogLevel::warn, std::forward<Args>(args)...); }
  template <class... Args>
  void error(Args&&... args) const { log(LogLevel::error, std::forward<Args>(args)...); }

  const std::string& name() const { return name_; }
  void set_level(LogLevel level) { level_ = level; }

 private:
  template <class... Args>
  void log(LogLevel level, Args&&... args) const {
    if (level < level_) return;
    std::ostringstream text;
    (text << ... << std::forward<Args>(args));
    write(level, text.str());
  }
  void write(LogLevel level, const std::string& text) const;

  std::string name_;
  LogLevel level_;
};

}  // namespace avs::runtime
