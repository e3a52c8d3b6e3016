// Modbus TCP framing of the drive client's requests and the checks every reply passes before
// any of its data is used (issue 20 1.5): libmodbus 3.1.6's TCP client checks the transaction
// and protocol ids but neither the MBAP unit id nor the MBAP length, so a reply naming another
// axis, or claiming 0xFFFF bytes, was taken as the answer. Pure functions, no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace avs::servo {

inline constexpr std::size_t mbap_header_bytes = 7;  ///< transaction, protocol, length, unit
inline constexpr std::size_t max_pdu_bytes = 253;   ///< Modbus application protocol, 4.1

/// The bytes of a PDU or an ADU, held inline (a Modbus TCP ADU is at most 260 bytes), so that
/// a cyclic exchange allocates nothing (issue 16 section 3).
class FrameBytes {
 public:
  static constexpr std::size_t capacity = mbap_header_bytes + max_pdu_bytes;
  void push_back(std::uint8_t b) {
    if (size_ == capacity) throw std::length_error("Modbus frame longer than 260 bytes");
    bytes_[size_++] = b;
  }
  const std::uint8_t* data() const { return bytes_.data(); }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::uint8_t front() const { return bytes_[0]; }
  const std::uint8_t* begin() const { return bytes_.data(); }
  const std::uint8_t* end() const { return bytes_.data() + size_; }
  std::uint8_t operator[](std::size_t i) const { return bytes_[i]; }
  std::span<const std::uint8_t> span() const { return {bytes_.data(), size_}; }

 private:
  std::array<std::uint8_t, capacity> bytes_{};
  std::size_t size_ = 0;
};

/// One request PDU (function code first) and what its reply must carry.
struct RequestPdu {
  FrameBytes bytes;
  std::uint16_t read_count = 0;     ///< registers the reply carries (0x03, 0x17)
  std::uint16_t write_address = 0;  ///< 0x10: echoed by the reply
  std::uint16_t write_count = 0;    ///< 0x10: echoed by the reply
  std::uint8_t function() const { return bytes.empty() ? 0 : bytes.front(); }
  /// Size of a normal reply PDU (function code included).
  std::size_t reply_bytes() const;
};

RequestPdu read_registers_request(std::uint16_t address, std::uint16_t count);
RequestPdu write_registers_request(std::uint16_t address, std::span<const std::uint16_t> values);
RequestPdu write_read_registers_request(std::uint16_t write_address,
                                        std::span<const std::uint16_t> values,
                                        std::uint16_t read_address, std::uint16_t read_count);

/// MBAP header (protocol id 0, length = unit id + PDU) followed by the PDU.
FrameBytes encode_tcp_request(std::uint16_t transaction_id, std::uint8_t unit_id,
                              const RequestPdu& request);

enum class ReplyProblem : std::uint8_t {
  none,
  transaction_id,  ///< answers another (older) request
  protocol_id,     ///< not Modbus
  unit_id,         ///< from another unit (axis) than the one asked
  length,          ///< MBAP length does not match the reply the request asks for
  function_code,   ///< another function than requested
  byte_count,      ///< register data of another size, or a wrong 0x10 echo
  exception,       ///< a well-formed exception reply (not a framing problem)
};

struct ReplyCheck {
  ReplyProblem problem = ReplyProblem::none;
  std::string message;              ///< what was expected and what came; empty when fine
  std::uint8_t exception_code = 0;  ///< for ReplyProblem::exception
  bool ok() const { return problem == ReplyProblem::none; }
};

/// Checks a reply's 7-byte MBAP header against the request: transaction id, protocol id 0,
/// unit id, and a length that is exactly that of the expected reply or of an exception reply.
/// On success `pdu_bytes` is the number of PDU bytes that follow.
ReplyCheck check_tcp_reply_header(std::span<const std::uint8_t> header,
                                  std::uint16_t transaction_id, std::uint8_t unit_id,
                                  const RequestPdu& request, std::size_t& pdu_bytes);

/// Checks a reply PDU: function code (or its exception, 0x80 | function), exact size, byte
/// count (reads) or the echoed address and quantity (0x10), and decodes the registers read
/// into `registers` (at least request.read_count long).
ReplyCheck check_reply_pdu(std::span<const std::uint8_t> pdu, const RequestPdu& request,
                           std::span<std::uint16_t> registers);

}  // namespace avs::servo
