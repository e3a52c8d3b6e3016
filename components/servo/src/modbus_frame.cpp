#include "avs/servo/modbus_frame.hpp"

#include <cstdio>

namespace avs::servo {
namespace {

constexpr std::uint8_t fc_read_holding = 0x03;
constexpr std::uint8_t fc_write_multiple = 0x10;
constexpr std::uint8_t fc_write_read = 0x17;
constexpr std::size_t exception_reply_bytes = 2;  ///< function | 0x80, exception code

void put_u16(FrameBytes& out, std::uint16_t value) {
  out.push_back(static_cast<std::uint8_t>(value >> 8));
  out.push_back(static_cast<std::uint8_t>(value & 0xFF));
}

std::uint16_t get_u16(std::span<const std::uint8_t> bytes, std::size_t at) {
  return static_cast<std::uint16_t>((bytes[at] << 8) | bytes[at + 1]);
}

ReplyCheck problem(ReplyProblem kind, const char* format, unsigned expected, unsigned got) {
  char text[160];
  std::snprintf(text, sizeof text, format, expected, got);
  return {kind, text, 0};
}

}  // namespace

std::size_t RequestPdu::reply_bytes() const {
  switch (function()) {
    case fc_read_holding:
    case fc_write_read:
      return 2 + 2 * std::size_t{read_count};  // function, byte count, registers
    case fc_write_multiple:
      return 5;  // function, address, quantity
    default:
      return 0;
  }
}

RequestPdu read_registers_request(std::uint16_t address, std::uint16_t count) {
  RequestPdu r;
  r.bytes.push_back(fc_read_holding);
  put_u16(r.bytes, address);
  put_u16(r.bytes, count);
  r.read_count = count;
  return r;
}

RequestPdu write_registers_request(std::uint16_t address, std::span<const std::uint16_t> values) {
  RequestPdu r;
  r.bytes.push_back(fc_write_multiple);
  put_u16(r.bytes, address);
  put_u16(r.bytes, static_cast<std::uint16_t>(values.size()));
  r.bytes.push_back(static_cast<std::uint8_t>(2 * values.size()));
  for (std::uint16_t v : values) put_u16(r.bytes, v);
  r.write_address = address;
  r.write_count = static_cast<std::uint16_t>(values.size());
  return r;
}

RequestPdu write_read_registers_request(std::uint16_t write_address,
                                        std::span<const std::uint16_t> values,
                                        std::uint16_t read_address, std::uint16_t read_count) {
  RequestPdu r;
  r.bytes.push_back(fc_write_read);
  put_u16(r.bytes, read_address);
  put_u16(r.bytes, read_count);
  put_u16(r.bytes, write_address);
  put_u16(r.bytes, static_cast<std::uint16_t>(values.size()));
  r.bytes.push_back(static_cast<std::uint8_t>(2 * values.size()));
  for (std::uint16_t v : values) put_u16(r.bytes, v);
  r.read_count = read_count;
  return r;
}

FrameBytes encode_tcp_request(std::uint16_t transaction_id, std::uint8_t unit_id,
                              const RequestPdu& request) {
  FrameBytes adu;
  put_u16(adu, transaction_id);
  put_u16(adu, 0);  // protocol id: Modbus
  put_u16(adu, static_cast<std::uint16_t>(1 + request.bytes.size()));
  adu.push_back(unit_id);
  for (const std::uint8_t b : request.bytes) adu.push_back(b);
  return adu;
}

ReplyCheck check_tcp_reply_header(std::span<const std::uint8_t> header,
                                  std::uint16_t transaction_id, std::uint8_t unit_id,
                                  const RequestPdu& request, std::size_t& pdu_bytes) {
  pdu_bytes = 0;
  if (header.size() != mbap_header_bytes) {
    return problem(ReplyProblem::length, "MBAP header of %u bytes expected, got %u",
                   static_cast<unsigned>(mbap_header_bytes), static_cast<unsigned>(header.size()));
  }
  if (get_u16(header, 0) != transaction_id) {
    return problem(ReplyProblem::transaction_id, "transaction id %u expected, got %u",
                   transaction_id, get_u16(header, 0));
  }
  if (get_u16(header, 2) != 0) {
    return problem(ReplyProblem::protocol_id, "protocol id %u expected, got %u", 0,
                   get_u16(header, 2));
  }
  // The unit id says which drive answered: data from another axis must never be taken.
  if (header[6] != unit_id) {
    return problem(ReplyProblem::unit_id, "unit id %u expected, got %u", unit_id, header[6]);
  }
  // Only two lengths are possible: the reply asked for, or an exception. Anything else (e.g.
  // 0xFFFF) is refused before reading on, so it cannot make us wait for, or read, a
  // following reply as part of this one.
  const std::size_t length = get_u16(header, 4);
  const std::size_t expected = 1 + request.reply_bytes();
  if (length != expected && length != 1 + exception_reply_bytes) {
    return problem(ReplyProblem::length, "MBAP length %u expected, got %u",
                   static_cast<unsigned>(expected), static_cast<unsigned>(length));
  }
  pdu_bytes = length - 1;
  return {};
}

ReplyCheck check_reply_pdu(std::span<const std::uint8_t> pdu, const RequestPdu& request,
                           std::span<std::uint16_t> registers) {
  const std::uint8_t function = request.function();
  if (pdu.empty()) return problem(ReplyProblem::length, "PDU of %u bytes expected, got %u",
                                  static_cast<unsigned>(request.reply_bytes()), 0);
  if (pdu[0] == (function | 0x80) && pdu.size() == exception_reply_bytes) {
    ReplyCheck c = problem(ReplyProblem::exception, "exception 0x%02X to function 0x%02X", pdu[1],
                           function);
    c.exception_code = pdu[1];
    return c;
  }
  if (pdu[0] != function) {
    return problem(ReplyProblem::function_code, "function 0x%02X expected, got 0x%02X", function,
                   pdu[0]);
  }
  if (pdu.size() != request.reply_bytes()) {
    return problem(ReplyProblem::length, "PDU of %u bytes expected, got %u",
                   static_cast<unsigned>(request.reply_bytes()),
                   static_cast<unsigned>(pdu.size()));
  }
  if (function == fc_write_multiple) {
    if (get_u16(pdu, 1) != request.write_address || get_u16(pdu, 3) != request.write_count) {
      return problem(ReplyProblem::byte_count, "write echo of %u registers expected, got %u",
                     request.write_count, get_u16(pdu, 3));
    }
    return {};
  }
  if (pdu[1] != 2 * request.read_count) {
    return problem(ReplyProblem::byte_count, "byte count %u expected, got %u",
                   2u * request.read_count, pdu[1]);
  }
  if (registers.size() < request.read_count) {
    return problem(ReplyProblem::byte_count, "room for %u registers expected, got %u",
                   request.read_count, static_cast<unsigned>(registers.size()));
  }
  for (std::size_t i = 0; i < request.read_count; ++i) registers[i] = get_u16(pdu, 2 + 2 * i);
  return {};
}

}  // namespace avs::servo
