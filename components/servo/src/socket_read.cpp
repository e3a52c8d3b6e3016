#include "avs/servo/socket_read.hpp"

#include <algorithm>
#include <cerrno>

#include <poll.h>
#include <sys/socket.h>

namespace avs::servo {

bool wait_readable(int fd, std::chrono::steady_clock::time_point deadline) {
  const auto left = std::max(deadline - std::chrono::steady_clock::now(),
                             std::chrono::steady_clock::duration::zero());
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
  timespec timeout{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  pollfd p{fd, POLLIN, 0};
  return ::ppoll(&p, 1, &timeout, nullptr) > 0;
}

ReadResult read_exact(int fd, std::span<std::uint8_t> out,
                      std::chrono::steady_clock::time_point deadline) {
  std::size_t done = 0;
  while (done < out.size()) {
    if (!wait_readable(fd, deadline)) return ReadResult::timeout;
    const ssize_t n = ::recv(fd, out.data() + done, out.size() - done, 0);
    if (n == 0) return ReadResult::closed;
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return ReadResult::closed;
    }
    done += static_cast<std::size_t>(n);
  }
  return ReadResult::ok;
}

}  // namespace avs::servo
