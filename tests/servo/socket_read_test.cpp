// The drive client's reads by a deadline: a reply already in the socket is read even when the
// reader comes after its deadline (its thread was preempted), so only a peer that did not answer
// in time counts as a timeout (the soak's drive/timeouts, docs/reliability.md).
#include "avs/servo/socket_read.hpp"

#include <array>
#include <chrono>

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include "avs/servo/modbus_handle.hpp"

namespace avs::servo {
namespace {

using Clock = std::chrono::steady_clock;

struct SocketPair {
  Socket reader, writer;
  SocketPair() {
    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) throw std::runtime_error("socketpair");
    reader = Socket(fds[0]);
    writer = Socket(fds[1]);
  }
  void write(std::span<const std::uint8_t> bytes) const {
    ASSERT_EQ(::write(writer.get(), bytes.data(), bytes.size()),
              static_cast<ssize_t>(bytes.size()));
  }
};

constexpr std::array<std::uint8_t, 8> kReply{0, 1, 0, 0, 0, 2, 1, 3};

TEST(SocketRead, AReplyAlreadyThereIsReadAfterTheDeadline) {
  SocketPair pair;
  pair.write(kReply);
  std::array<std::uint8_t, 8> got{};
  // The reader comes a whole second after its deadline: the reply was there all along.
  EXPECT_EQ(read_exact(pair.reader.get(), got, Clock::now() - std::chrono::seconds(1)),
            ReadResult::ok);
  EXPECT_EQ(got, kReply);
}

TEST(SocketRead, AHeaderThenItsRestAfterTheDeadline) {
  SocketPair pair;
  pair.write(kReply);
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  std::array<std::uint8_t, 6> header{};
  ASSERT_EQ(read_exact(pair.reader.get(), header, deadline), ReadResult::ok);
  // Preempted after the header for longer than the timeout: the PDU is in the socket.
  std::array<std::uint8_t, 2> pdu{};
  EXPECT_EQ(read_exact(pair.reader.get(), pdu, Clock::now() - std::chrono::milliseconds(10)),
            ReadResult::ok);
  EXPECT_EQ(pdu[0], 1);
  EXPECT_EQ(pdu[1], 3);
}

TEST(SocketRead, NothingThereIsATimeoutAndAShortReplyToo) {
  SocketPair pair;
  std::array<std::uint8_t, 8> got{};
  const auto before = Clock::now();
  EXPECT_EQ(read_exact(pair.reader.get(), got, Clock::now() + std::chrono::milliseconds(20)),
            ReadResult::timeout);
  EXPECT_GE(Clock::now() - before, std::chrono::milliseconds(20));  // it waited for the peer
  EXPECT_EQ(read_exact(pair.reader.get(), got, Clock::now() - std::chrono::seconds(1)),
            ReadResult::timeout);
  pair.write(std::span(kReply).first(3));
  EXPECT_EQ(read_exact(pair.reader.get(), got, Clock::now() - std::chrono::seconds(1)),
            ReadResult::timeout);
}

TEST(SocketRead, AClosedPeerIsClosed) {
  SocketPair pair;
  pair.writer.reset();
  std::array<std::uint8_t, 8> got{};
  EXPECT_EQ(read_exact(pair.reader.get(), got, Clock::now() + std::chrono::seconds(5)),
            ReadResult::closed);
}

}  // namespace
}  // namespace avs::servo
