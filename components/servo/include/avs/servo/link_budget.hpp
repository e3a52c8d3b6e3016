// What a Modbus RTU line can carry (reference section 1.3): wire time of the cyclic frames,
// inter-frame gaps t3.5 and the drive's turnaround, per axis and per cycle.
#pragma once

#include <string>

namespace avs::servo {

struct SerialLine {
  int baud = 115200;
  char parity = 'E';  ///< 'N', 'E' or 'O'
  int data_bits = 8;
  int stop_bits = 1;
};

/// Register counts of one axis's cyclic exchange.
struct ExchangeShape {
  int write_registers = 3;
  int read_registers = 9;
  bool write_read_0x17 = true;  ///< one 0x17 transaction, else 0x10 write + 0x03 read
};

struct LinkBudget {
  double char_bits = 11;
  int bytes_per_axis = 0;       ///< requests + responses, all frames of one axis
  int frames_per_axis = 0;      ///< each preceded by a t3.5 gap
  double gap_s = 0;             ///< t3.5
  double seconds_per_axis = 0;  ///< wire + gaps + turnaround
  double seconds_per_cycle = 0;
  double max_cycle_rate_hz = 0;
};

/// t3.5: 3.5 character times, or the spec's fixed 1.750 ms above 19200 baud.
LinkBudget rtu_link_budget(const SerialLine& line, const ExchangeShape& shape, int axes,
                           double drive_turnaround_s);

/// Empty when `cycle_rate_hz` fits, else one line explaining why not and what would fit.
std::string check_rtu_cycle_rate(const SerialLine& line, const ExchangeShape& shape, int axes,
                                 double drive_turnaround_s, double cycle_rate_hz);

}  // namespace avs::servo
