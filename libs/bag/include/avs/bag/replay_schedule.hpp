// When a bag player inside a graph publishes each recorded message (I/O-free): at the time it
// had in the recording, so that a lockstep graph reprocessing a bag sees every sample at the
// simulated time it saw live (docs/bag.md, "Replay inside a graph").
//
// A message whose type starts with a std_msgs/Header is due at its header stamp (the time the
// recording graph gave it: a camera frame's exposure). A message without a header is due at
// its log time moved onto the stamps' time line by the (stamp - log time) of the latest stamped
// message before it; before any stamped message, at once. Messages are never reordered: one is
// never due before the message ahead of it in the file (log-time order).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string_view>

namespace avs::bag {

/// Whether a ros2msg definition (as MCAP's ros2 profile stores it) begins with a field of
/// type std_msgs/Header (comments and blank lines skipped).
bool starts_with_header(std::string_view ros2msg);

/// The header stamp (ns) of a serialised sample whose type begins with std_msgs/Header: the
/// int32 sec and uint32 nanosec after the 4-byte encapsulation header, in the byte order it
/// names (plain CDR or XCDR2, either endianness). nullopt when the bytes are too short, the
/// encapsulation is not one of those, or nanosec is out of range.
std::optional<std::int64_t> header_stamp_ns(std::span<const std::byte> cdr);

class ReplaySchedule {
 public:
  enum class Clock {
    header,  ///< header stamps where the type has one (the default)
    log,     ///< log times only
  };

  /// due_ns() of a message whose place on the time line is unknown (no header, before the
  /// first stamped message): publish it at once.
  static constexpr std::int64_t kAtOnce = std::numeric_limits<std::int64_t>::min();

  explicit ReplaySchedule(Clock clock) : clock_(clock) {}

  /// The time (ns on the recording's time line) the next message of the file is due at, or
  /// kAtOnce. `stamp_ns`: its header stamp when its type has one, else nullopt.
  std::int64_t due_ns(std::int64_t log_time_ns, std::optional<std::int64_t> stamp_ns);

 private:
  Clock clock_;
  std::optional<std::int64_t> log_to_stamp_ns_;  ///< stamp - log time of the last stamped one
  std::optional<std::int64_t> last_due_ns_;
};

}  // namespace avs::bag
