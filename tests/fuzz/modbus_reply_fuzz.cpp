// libFuzzer target: the Modbus TCP reply path of the drive client without its socket: the
// MBAP header check, the PDU check and the decoding of the registers read into axis feedback
// (as DriveClient::exchange does). The first byte picks the request (0x03 read, 0x10 write,
// 0x17 write-and-read of the default map's registers), then come the reply's bytes.
#include <array>
#include <cstdlib>
#include <span>

#include "avs/servo/cia402.hpp"
#include "avs/servo/modbus_frame.hpp"
#include "avs/servo/register_map.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace avs::servo;
  if (size < 1 + mbap_header_bytes) return 0;
  static const RegisterMap map = default_register_map(pan_rated_torque_nm, 1e-5);
  const std::uint16_t count = map.register_count();
  const std::array<std::uint16_t, 3> writes{0x0f, 100, 7};
  RequestPdu request;
  switch (data[0] % 3) {
    case 0:
      request = read_registers_request(0, count);
      break;
    case 1:
      request = write_registers_request(0, writes);
      break;
    default:
      request = write_read_registers_request(0, writes, 0, count);
      break;
  }
  const std::uint16_t transaction_id = 0x0102;
  const std::uint8_t unit_id = 1;
  std::span<const std::uint8_t> reply(data + 1, size - 1);
  std::size_t pdu_bytes = 0;
  ReplyCheck check = check_tcp_reply_header(reply.first(mbap_header_bytes), transaction_id, unit_id,
                                            request, pdu_bytes);
  if (!check.ok()) return 0;
  if (pdu_bytes > reply.size() - mbap_header_bytes) return 0;  // the socket read would wait
  std::array<std::uint16_t, 256> registers{};
  check = check_reply_pdu(reply.subspan(mbap_header_bytes, pdu_bytes), request, registers);
  if (!check.ok() || request.read_count == 0) return 0;
  if (request.read_count > registers.size()) std::abort();
  for (const RegisterSpec& spec : map.specs) {
    if (!spec.present) continue;
    const std::int64_t counts = read_counts(spec, std::span<const std::uint16_t>(registers).subspan(
                                                      spec.address, spec.width_registers));
    (void)to_si(spec, counts);
  }
  (void)decode_statusword(registers[map[Signal::statusword].address]);
  return 0;
}
