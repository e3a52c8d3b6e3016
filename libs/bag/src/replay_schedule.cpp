#include "avs/bag/replay_schedule.hpp"

#include <algorithm>

namespace avs::bag {

bool starts_with_header(std::string_view ros2msg) {
  std::size_t pos = 0;
  while (pos < ros2msg.size()) {
    std::size_t end = ros2msg.find('\n', pos);
    if (end == std::string_view::npos) end = ros2msg.size();
    std::string_view line = ros2msg.substr(pos, end - pos);
    pos = end + 1;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#') continue;
    line.remove_prefix(first);
    const std::size_t space = line.find_first_of(" \t");
    const std::string_view type = line.substr(0, space);
    return type == "std_msgs/Header" || type == "std_msgs/msg/Header" || type == "Header";
  }
  return false;
}

std::optional<std::int64_t> header_stamp_ns(std::span<const std::byte> cdr) {
  if (cdr.size() < 12) return std::nullopt;
  // Encapsulation identifier (big-endian uint16): CDR_BE 0, CDR_LE 1, CDR2_BE 6, CDR2_LE 7 (a
  // final struct's members follow directly in each).
  const auto id = static_cast<unsigned>((std::to_integer<unsigned>(cdr[0]) << 8) |
                                        std::to_integer<unsigned>(cdr[1]));
  if (id != 0 && id != 1 && id != 6 && id != 7) return std::nullopt;
  const bool little = (id & 1u) != 0;
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) {
      const auto byte = std::to_integer<std::uint32_t>(cdr[at + static_cast<std::size_t>(i)]);
      v |= byte << (8 * (little ? i : 3 - i));
    }
    return v;
  };
  const auto sec = static_cast<std::int32_t>(u32(4));
  const std::uint32_t nanosec = u32(8);
  if (nanosec >= 1'000'000'000u) return std::nullopt;
  return static_cast<std::int64_t>(sec) * 1'000'000'000 + nanosec;
}

std::int64_t ReplaySchedule::due_ns(std::int64_t log_time_ns,
                                    std::optional<std::int64_t> stamp_ns) {
  std::int64_t due = 0;
  if (clock_ == Clock::log) {
    due = log_time_ns;
  } else if (stamp_ns) {
    due = *stamp_ns;
    log_to_stamp_ns_ = *stamp_ns - log_time_ns;
  } else if (log_to_stamp_ns_) {
    due = log_time_ns + *log_to_stamp_ns_;
  } else {
    due = last_due_ns_.value_or(kAtOnce);
  }
  if (last_due_ns_) due = std::max(due, *last_due_ns_);
  last_due_ns_ = due;
  return due;
}

}  // namespace avs::bag
