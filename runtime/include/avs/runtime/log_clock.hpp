// The wall-clock time as every log line shows it ("14:58:19.909", local time, milliseconds):
// one format for the logger and for tools whose records must be matched with log lines.
#pragma once

#include <chrono>
#include <string>

namespace avs::runtime {

std::string log_clock_text(std::chrono::system_clock::time_point when);

}  // namespace avs::runtime
