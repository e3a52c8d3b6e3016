// The reply checks of the drive client's Modbus TCP framing (issue 20 1.5), one rule each.
#include "avs/servo/modbus_frame.hpp"

#include <gtest/gtest.h>

#include <array>

namespace avs::servo {
namespace {

const std::array<std::uint16_t, 3> writes = {0x000F, 0x0123, 7};

RequestPdu cyclic_request() { return write_read_registers_request(0, writes, 4, 9); }

/// The reply a correct server sends: MBAP header then the 0x17 PDU with `count` registers.
std::vector<std::uint8_t> good_reply(std::uint16_t tid, std::uint8_t unit, std::uint8_t count) {
  std::vector<std::uint8_t> r = {static_cast<std::uint8_t>(tid >> 8),
                                 static_cast<std::uint8_t>(tid & 0xFF),
                                 0,
                                 0,
                                 0,
                                 static_cast<std::uint8_t>(3 + 2 * count),
                                 unit,
                                 0x17,
                                 static_cast<std::uint8_t>(2 * count)};
  for (std::uint8_t i = 0; i < count; ++i) {
    r.push_back(0);
    r.push_back(static_cast<std::uint8_t>(i + 1));
  }
  return r;
}

ReplyCheck check(const std::vector<std::uint8_t>& reply, std::uint16_t tid, std::uint8_t unit,
                 std::array<std::uint16_t, 9>& regs) {
  const RequestPdu request = cyclic_request();
  std::size_t pdu_bytes = 0;
  const ReplyCheck header = check_tcp_reply_header(
      std::span(reply).first(mbap_header_bytes), tid, unit, request, pdu_bytes);
  if (!header.ok()) return header;
  EXPECT_EQ(pdu_bytes, reply.size() - mbap_header_bytes);
  return check_reply_pdu(std::span(reply).subspan(mbap_header_bytes), request, regs);
}

TEST(ModbusFrame, EncodesTheWriteReadRequest) {
  const FrameBytes frame = encode_tcp_request(0x0102, 2, cyclic_request());
  const std::vector<std::uint8_t> adu(frame.begin(), frame.end());
  const std::vector<std::uint8_t> expected = {0x01, 0x02, 0, 0, 0, 17, 2,    0x17, 0, 4, 0, 9,
                                              0,    0,    0, 3, 6, 0, 0x0F, 0x01, 0x23, 0, 7};
  EXPECT_EQ(adu, expected);
}

TEST(ModbusFrame, AcceptsTheRightReplyAndDecodesIt) {
  std::array<std::uint16_t, 9> regs{};
  EXPECT_TRUE(check(good_reply(5, 1, 9), 5, 1, regs).ok());
  EXPECT_EQ(regs[0], 1);
  EXPECT_EQ(regs[8], 9);
}

TEST(ModbusFrame, RejectsAnotherUnitId) {
  std::array<std::uint16_t, 9> regs{};
  const ReplyCheck c = check(good_reply(5, 2, 9), 5, 1, regs);
  EXPECT_EQ(c.problem, ReplyProblem::unit_id);
  EXPECT_NE(c.message.find("unit id 1 expected, got 2"), std::string::npos) << c.message;
  EXPECT_EQ(regs[0], 0) << "no data taken from a rejected reply";
}

TEST(ModbusFrame, RejectsALengthOfFFFFAndAnyOtherWrongLength) {
  std::array<std::uint16_t, 9> regs{};
  auto reply = good_reply(5, 1, 9);
  reply[4] = reply[5] = 0xFF;
  EXPECT_EQ(check(reply, 5, 1, regs).problem, ReplyProblem::length);
  reply = good_reply(5, 1, 8);  // consistent frame, one register short
  EXPECT_EQ(check(reply, 5, 1, regs).problem, ReplyProblem::length);
}

TEST(ModbusFrame, RejectsAnOldTransactionAndAnotherProtocol) {
  std::array<std::uint16_t, 9> regs{};
  EXPECT_EQ(check(good_reply(4, 1, 9), 5, 1, regs).problem, ReplyProblem::transaction_id);
  auto reply = good_reply(5, 1, 9);
  reply[3] = 1;
  EXPECT_EQ(check(reply, 5, 1, regs).problem, ReplyProblem::protocol_id);
}

TEST(ModbusFrame, RejectsAnotherFunctionOrByteCount) {
  std::array<std::uint16_t, 9> regs{};
  auto reply = good_reply(5, 1, 9);
  reply[7] = 0x03;
  EXPECT_EQ(check(reply, 5, 1, regs).problem, ReplyProblem::function_code);
  reply = good_reply(5, 1, 9);
  reply[8] = 16;  // claims 8 registers in a frame of 9
  EXPECT_EQ(check(reply, 5, 1, regs).problem, ReplyProblem::byte_count);
}

TEST(ModbusFrame, ReportsAnExceptionReply) {
  std::array<std::uint16_t, 9> regs{};
  const std::vector<std::uint8_t> reply = {0, 5, 0, 0, 0, 3, 1, 0x97, 0x02};
  const ReplyCheck c = check(reply, 5, 1, regs);
  EXPECT_EQ(c.problem, ReplyProblem::exception);
  EXPECT_EQ(c.exception_code, 0x02);
}

TEST(ModbusFrame, ChecksTheEchoOfAMultipleWrite) {
  const RequestPdu request = write_registers_request(0x10, writes);
  std::vector<std::uint8_t> pdu = {0x10, 0, 0x10, 0, 3};
  EXPECT_TRUE(check_reply_pdu(pdu, request, {}).ok());
  pdu[4] = 2;
  EXPECT_EQ(check_reply_pdu(pdu, request, {}).problem, ReplyProblem::byte_count);
}

}  // namespace
}  // namespace avs::servo
