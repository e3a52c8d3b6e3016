#include "avs/servo/link_budget.hpp"

#include <cstdio>

namespace avs::servo {

LinkBudget rtu_link_budget(const SerialLine& line, const ExchangeShape& shape, int axes,
                           double drive_turnaround_s) {
  LinkBudget b;
  b.char_bits = 1.0 + line.data_bits + (line.parity == 'N' ? 0 : 1) + line.stop_bits;
  const int nw = shape.write_registers;
  const int nr = shape.read_registers;
  // RTU frame = address + PDU + CRC16.
  if (shape.write_read_0x17) {
    // request: addr fc rd_start(2) rd_qty(2) wr_start(2) wr_qty(2) byte_count data crc(2)
    // response: addr fc byte_count data crc(2)
    b.bytes_per_axis = (13 + 2 * nw) + (5 + 2 * nr);
    b.frames_per_axis = 2;
  } else {
    // 0x10: addr fc start(2) qty(2) byte_count data crc(2); response addr fc start qty crc = 8
    // 0x03: request 8 bytes; response addr fc byte_count data crc(2)
    b.bytes_per_axis = (9 + 2 * nw) + 8 + 8 + (5 + 2 * nr);
    b.frames_per_axis = 4;
  }
  const double char_s = b.char_bits / line.baud;
  b.gap_s = line.baud > 19200 ? 1.750e-3 : 3.5 * char_s;
  const int transactions = shape.write_read_0x17 ? 1 : 2;
  b.seconds_per_axis =
      b.bytes_per_axis * char_s + b.frames_per_axis * b.gap_s + transactions * drive_turnaround_s;
  b.seconds_per_cycle = b.seconds_per_axis * axes;
  b.max_cycle_rate_hz = b.seconds_per_cycle > 0 ? 1.0 / b.seconds_per_cycle : 0;
  return b;
}

std::string check_rtu_cycle_rate(const SerialLine& line, const ExchangeShape& shape, int axes,
                                 double drive_turnaround_s, double cycle_rate_hz) {
  const LinkBudget b = rtu_link_budget(line, shape, axes, drive_turnaround_s);
  if (cycle_rate_hz <= b.max_cycle_rate_hz) return {};
  char msg[512];
  std::snprintf(msg, sizeof msg,
                "servo_drive: cycle rate %.0f Hz is more than the RTU link can carry: %d axes x "
                "%d bytes (%s) at %d baud %d%c%d with t3.5 = %.3f ms and %.3f ms turnaround need "
                "%.3f ms per cycle, so at most %.1f Hz",
                cycle_rate_hz, axes, b.bytes_per_axis,
                shape.write_read_0x17 ? "0x17" : "0x10 + 0x03", line.baud, line.data_bits,
                line.parity, line.stop_bits, b.gap_s * 1e3, drive_turnaround_s * 1e3,
                b.seconds_per_cycle * 1e3, b.max_cycle_rate_hz);
  return msg;
}

}  // namespace avs::servo
