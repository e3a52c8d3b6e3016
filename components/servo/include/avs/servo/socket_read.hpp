// Reading a Modbus TCP reply from a socket by a deadline: the drive client's cyclic path, which
// bypasses libmodbus's reads to tell a late reply from a missing one (issue 16 section 3).
#pragma once

#include <chrono>
#include <cstdint>
#include <span>

namespace avs::servo {

enum class ReadResult : std::uint8_t { ok, timeout, closed };

/// True when `fd` is readable by `deadline` (steady clock). Past the deadline it still looks
/// once, without waiting: bytes already in the socket are a reply that came in time and a
/// reader that came late (its thread preempted between send and poll, or between a reply's
/// header and its PDU), which is not a timeout of the peer.
bool wait_readable(int fd, std::chrono::steady_clock::time_point deadline);

/// Reads exactly out.size() bytes by `deadline` (wait_readable before each read).
ReadResult read_exact(int fd, std::span<std::uint8_t> out,
                      std::chrono::steady_clock::time_point deadline);

}  // namespace avs::servo
