// Time points and durations in nanoseconds, on either wall or simulated time.
#pragma once

#include <chrono>
#include <cstdint>

namespace avs::runtime {

using Duration = std::chrono::nanoseconds;

/// Nanoseconds since the epoch of the clock that produced it (Unix epoch for wall time,
/// start of simulation for sim time). Matches builtin_interfaces/Time after splitting.
struct Time {
  std::int64_t ns = 0;

  friend constexpr auto operator<=>(Time, Time) = default;
  friend constexpr Time operator+(Time t, Duration d) { return {t.ns + d.count()}; }
  friend constexpr Duration operator-(Time a, Time b) { return Duration(a.ns - b.ns); }
  constexpr double seconds() const { return static_cast<double>(ns) * 1e-9; }
};

/// Fills a builtin_interfaces::msg::dds_::Time_ (or any struct with sec/nanosec).
template <class RosTime>
void to_ros_time(Time t, RosTime& out) {
  std::int64_t sec = t.ns / 1'000'000'000;
  std::int64_t rem = t.ns % 1'000'000'000;
  if (rem < 0) {
    rem += 1'000'000'000;
    --sec;
  }
  out.sec = static_cast<decltype(out.sec)>(sec);
  out.nanosec = static_cast<decltype(out.nanosec)>(rem);
}

template <class RosTime>
Time from_ros_time(const RosTime& in) {
  return {static_cast<std::int64_t>(in.sec) * 1'000'000'000 + static_cast<std::int64_t>(in.nanosec)};
}

}  // namespace avs::runtime
