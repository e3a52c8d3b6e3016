// The host side of the servo amplifiers: a libmodbus client (TCP or RTU) that runs the cyclic
// exchange for one or more axes, drives each axis's CiA 402 state machine, and applies the
// safety rules (safety.hpp) to every torque it writes. No threads of its own: cycle() is
// called by the owner's cyclic thread (or a simulation in lockstep) with the current time;
// set_command()/set_estop() may be called from other threads.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "avs/servo/cia402.hpp"
#include "avs/servo/link_budget.hpp"
#include "avs/servo/modbus_frame.hpp"
#include "avs/servo/modbus_handle.hpp"
#include "avs/servo/register_map.hpp"
#include "avs/servo/safety.hpp"
#include "avs/servo/statistics.hpp"

namespace avs::servo {

enum class Transport : std::uint8_t { tcp, rtu };

struct TcpLinkConfig {
  std::string host = "127.0.0.1";
  int port = 502;
};

struct RtuLinkConfig {
  std::string device = "/dev/ttyUSB0";
  SerialLine line;                     ///< baud, parity, data and stop bits
  bool rs485 = true;                   ///< modbus_rtu_set_serial_mode(MODBUS_RTU_RS485)
  int rts = MODBUS_RTU_RTS_NONE;       ///< MODBUS_RTU_RTS_NONE / _UP / _DOWN (direction pin)
  int rts_delay_us = -1;               ///< -1: libmodbus default
  double drive_turnaround_s = 0.0005;  ///< drive's reply delay, used by the link budget
};

enum class EstopAction : std::uint8_t {
  disable_operation,  ///< torque 0 and controlword 0x07: torque off at once (default)
  quick_stop,         ///< torque 0 and controlword 0x02: the drive brakes per 0x605A
};

struct DriveAxisConfig {
  std::string name = "pan";
  int unit_id = 1;
  RegisterMap registers;  ///< must be complete (see default_register_map)
  AxisSafetyConfig safety;
  std::int16_t mode_of_operation = mode_cyclic_synchronous_torque;
};

struct DriveClientConfig {
  Transport transport = Transport::tcp;
  TcpLinkConfig tcp;
  RtuLinkConfig rtu;
  std::vector<DriveAxisConfig> axes;
  double cycle_rate_hz = 1000.0;
  double response_timeout_s = 0.0005;  ///< must be below the period (see below)
  /// Refuse response_timeout_s x axes >= period (real time). Off only in lockstep simulation,
  /// where the wait costs wall time but no simulated time, and a generous wall timeout keeps a
  /// loaded machine from turning a slow reply into a (non-deterministic) link fault.
  bool require_timeout_within_period = true;
  /// Response timeout while configuring (connect and reconnect: probe, mode, limits), which is
  /// not cyclic: a loaded host must not fail the configuration for a reply a little slower than
  /// the cyclic budget. The larger of this and response_timeout_s applies.
  double configure_timeout_s = 0.05;
  /// Stale-command limit (stamp or arrival older -> zero torque) and the tolerance for stamps
  /// ahead of the arrival time (later ones are rejected and counted).
  CommandFreshness command_freshness;
  /// A drive fault latches zero torque until a reset request and this many consecutive
  /// cycles of Operation enabled (FaultLatch).
  int fault_clear_stable_cycles = 5;
  bool use_write_read_0x17 = true;  ///< else 0x10 write(s) + 0x03 read
  double reconnect_backoff_initial_s = 0.005;
  double reconnect_backoff_max_s = 0.5;
  EstopAction estop_action = EstopAction::disable_operation;
  bool auto_fault_reset = false;  ///< reset drive faults without request_fault_reset()
};

/// What a running drive client may change (servo_drive's live parameters, issue 18): the
/// command rules, the e-stop action, automatic fault reset and each axis's host-side
/// soft-limit rules. The rest of AxisSafetyConfig stays as connected: the torque limit is
/// written to the drive at connect, the motor, inertia and gearing describe the hardware.
struct DriveLiveSettings {
  CommandFreshness command_freshness;
  EstopAction estop_action = EstopAction::disable_operation;
  bool auto_fault_reset = false;
  std::vector<AxisSafetyConfig> safety;  ///< one per axis, in the configuration's order
};

/// Default two-axis configuration for the simulated amplifier (pan unit 1, tilt unit 2).
DriveClientConfig default_drive_client_config(const std::string& host, int port);

struct AxisFeedback {
  bool valid = false;  ///< from this cycle's successful exchange
  double q_rad = 0;
  double qd_rad_s = 0;
  double torque_actual_nm = 0;
  std::uint16_t statusword = 0;
  DriveState state = DriveState::not_ready_to_switch_on;
  std::uint16_t error_code = 0;
  double commanded_torque_nm = 0;  ///< what this cycle wrote (0 when not written)
  std::uint16_t controlword = 0;   ///< what this cycle wrote
  std::uint32_t safety_reasons = safety_none;
  bool fault_latched = false;  ///< FaultLatch: zero torque until reset and a stable enable
};

struct CycleResult {
  bool link_ok = false;       ///< every axis exchanged and checked
  bool link_fault = false;    ///< a fault happened or the link is down / backing off
  std::string fault_message;  ///< the first fault of this cycle, with axis and cause
  std::vector<AxisFeedback> axes;
};

struct LinkStatistics {
  std::uint64_t exchanges = 0;  ///< successful, checked axis exchanges
  std::uint64_t timeouts = 0;
  /// TCP: axis exchanges whose reply missed the response timeout once (issue 16 section 3):
  /// the cycle goes on without that axis's feedback, the drive keeps the torque last written
  /// for that period, no link fault. A second miss in a row (no valid reply for 2 periods), or
  /// a miss while a late reply is still due, is a link fault.
  std::uint64_t missed_cycles = 0;
  std::uint64_t late_replies = 0;   ///< replies that came after their timeout: read and dropped
  std::uint64_t exceptions = 0;     ///< Modbus exception replies
  std::uint64_t stale_replies = 0;  ///< echo counter mismatch
  /// Replies that do not answer the request: wrong unit id, transaction or protocol id,
  /// length, function code or byte count (TCP: checked here; RTU: by libmodbus).
  std::uint64_t bad_replies = 0;
  std::uint64_t errors = 0;      ///< other I/O errors (reset, broken pipe, bad data)
  std::uint64_t reconnects = 0;  ///< successful re-connections after a fault
  std::uint64_t connect_failures = 0;
  double rtt_us_p50 = 0;  ///< per axis exchange, over the recent window
  double rtt_us_p99 = 0;
};

/// Torque commands refused by set_command().
struct CommandStatistics {
  std::uint64_t accepted = 0;
  std::uint64_t future_stamped = 0;     ///< stamp ahead of the arrival beyond the tolerance
  std::uint64_t before_activation = 0;  ///< stamped before activation / e-stop release
  double last_future_ahead_s = 0;       ///< stamp - arrival of the last future-stamped one
};

class DriveClient {
 public:
  /// Validates the configuration (register maps, timeouts, RTU link budget); throws
  /// ConfigError with one explanatory line when it is refused.
  explicit DriveClient(DriveClientConfig config);
  ~DriveClient();
  DriveClient(const DriveClient&) = delete;
  DriveClient& operator=(const DriveClient&) = delete;

  /// Configure: connects, checks the word order probe, writes mode and drive torque limits.
  /// Throws ModbusError/ConfigError naming the axis on failure.
  void connect();
  /// Closes the link after writing controlword 0 (disable voltage) to every axis, best effort.
  void disconnect();

  /// Enable on activate: from the next cycles, 0x06 -> 0x07 -> 0x0F gated on the statusword,
  /// with torque 0 until enabled; commands stamped before `now_s` are discarded.
  void activate(double now_s);
  /// Disable on deactivate: torque 0 and 0x07 (Switched on).
  void deactivate();
  /// Resets latched faults: a drive in Fault gets the bit-7 edge; a latched axis gets torque
  /// again once its drive has been Operation enabled for fault_clear_stable_cycles.
  void request_fault_reset();
  /// E-stop: from the next cycle torque 0 (and the estop action). Releasing it discards
  /// commands stamped before `now_s`.
  void set_estop(bool active, double now_s);
  /// Latest torque command (motor N m, one per axis) stamped with the sender's time, received
  /// at `arrival_s` (our clock). Returns false (and counts it) when it is refused: stamped
  /// before activation / e-stop release, or later than the arrival plus the tolerance.
  bool set_command(const std::vector<double>& torque_nm, double stamp_s, double arrival_s);

  /// Takes `live` from the start of the next cycle (never within one); thread-safe. Throws
  /// ConfigError, changing nothing, when it has the wrong number of axes or an axis's soft
  /// lower limit is not below its upper one.
  void retune(const DriveLiveSettings& live);

  /// One cyclic exchange with every axis at time now_s (same time base as the stamps).
  CycleResult cycle(double now_s);
  /// The same into `result`, reusing its memory: a healthy cycle allocates nothing once
  /// `result` has held one (issue 16 section 3; the servo_drive component's form).
  void cycle(double now_s, CycleResult& result);

  LinkStatistics statistics() const;
  CommandStatistics command_statistics() const;
  const DriveClientConfig& config() const { return config_; }
  bool connected() const { return ctx_ != nullptr; }
  /// Non-empty once a reconnect found a configuration mismatch (e.g. word order): the client
  /// stops retrying and every cycle reports this.
  const std::string& fatal_error() const { return fatal_error_; }

 private:
  struct WriteRun {
    std::uint16_t address = 0;
    std::uint16_t count = 0;
  };
  struct AxisRuntime {
    std::vector<WriteRun> write_runs;
    std::uint16_t read_address = 0;
    std::uint16_t read_count = 0;
    std::uint16_t counter = 0;
    AxisFeedback last;        ///< last good feedback
    double last_time_s = 0;   ///< when `last` was read
    int reset_phase = 0;      ///< fault reset edge: 0 write bit 7 low, 1 write bit 7 high
    int missed_in_a_row = 0;  ///< exchanges whose reply missed the timeout, consecutively
    FaultLatch latch;
  };
  enum class ExchangeError : std::uint8_t { none, timeout, exception, stale, bad_reply, io };

  void open_link();       ///< throws
  void configure_axes();  ///< throws
  void close_link();
  std::uint16_t next_controlword(std::size_t axis, bool want_enabled, bool estop, bool reset);
  ExchangeError exchange(std::size_t axis, std::uint16_t controlword, double torque_nm,
                         AxisFeedback& feedback, std::string& message);
  /// TCP: one request and its reply over the connected socket, the reply checked in full
  /// (modbus_frame.hpp) before any register is taken.
  ExchangeError tcp_transaction(std::uint8_t unit_id, const RequestPdu& request,
                                std::span<std::uint16_t> registers, std::string& message,
                                double timeout_s);
  /// A configure-time read or write of `axis`, checked like the cyclic exchanges (over TCP
  /// through tcp_transaction: unit id, transaction id, length); throws ModbusError naming
  /// `what` when it fails.
  void configure_read(const DriveAxisConfig& axis, std::uint16_t address,
                      std::span<std::uint16_t> registers, const std::string& what);
  void configure_write(const DriveAxisConfig& axis, std::uint16_t address,
                       std::span<const std::uint16_t> values, const std::string& what);
  /// The reply budget while connecting (drives answer configuration writes slower).
  double configure_timeout_s() const {
    return std::max(config_.configure_timeout_s, config_.response_timeout_s);
  }
  static ExchangeError classify_modbus_errno(int err);
  void on_link_fault(double now_s, ExchangeError error, const std::string& message);

  DriveClientConfig config_;
  std::vector<AxisRuntime> axes_;
  ModbusContext ctx_;
  double next_connect_s_ = -std::numeric_limits<double>::infinity();
  double backoff_s_ = 0;
  bool had_fault_ = false;
  std::uint16_t transaction_id_ = 0;  ///< of our own TCP requests
  /// A request whose reply missed its timeout: that reply may still come, before the next.
  bool late_reply_due_ = false;
  std::uint16_t late_transaction_id_ = 0;
  std::string fatal_error_;  ///< configuration mismatch found on reconnect: no more retries

  mutable std::mutex command_mutex_;  ///< guards the fields below and stats_
  std::vector<double> command_nm_;
  std::vector<double> command_snapshot_;  ///< cycle()'s copy, sized once (no allocation)
  double command_stamp_s_ = std::numeric_limits<double>::quiet_NaN();
  double command_arrival_s_ = std::numeric_limits<double>::quiet_NaN();
  double accept_after_s_ = -std::numeric_limits<double>::infinity();
  bool want_enabled_ = false;
  bool estop_ = false;
  bool fault_reset_requested_ = false;
  std::optional<DriveLiveSettings> retuned_;  ///< taken by the next cycle
  LinkStatistics stats_;
  CommandStatistics command_stats_;
  SampleWindow rtt_us_;
};

}  // namespace avs::servo
