#include "avs/servo/drive_client.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include "avs/servo/modbus_frame.hpp"
#include "avs/servo/plant.hpp"
#include "avs/servo/socket_read.hpp"

namespace avs::servo {
namespace {

constexpr Signal cyclic_writes[] = {Signal::controlword, Signal::target_torque,
                                    Signal::host_counter};
constexpr Signal cyclic_reads[] = {
    Signal::statusword,      Signal::mode_display,    Signal::torque_actual, Signal::error_code,
    Signal::position_actual, Signal::velocity_actual, Signal::echo_counter};

/// The envelope's physical model of an axis: the plant model's inertia, gear and efficiency.
void set_envelope_model(AxisSafetyConfig& safety, const AxisPlantConfig& plant) {
  safety.output_inertia_kg_m2 = plant.inertia_kgm2;
  safety.gear_ratio = plant.gear_ratio;
  safety.gear_efficiency = plant.efficiency;
}

std::string axis_label(const DriveAxisConfig& axis) {
  return "axis " + axis.name + " (unit " + std::to_string(axis.unit_id) + ")";
}

double monotonic_us() {
  return std::chrono::duration<double, std::micro>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

DriveClientConfig default_drive_client_config(const std::string& host, int port) {
  DriveClientConfig c;
  c.tcp.host = host;
  c.tcp.port = port;
  const double pan_rad_per_count = AxisPlant(pan_plant_config()).output_rad_per_count();
  const double tilt_rad_per_count = AxisPlant(tilt_plant_config()).output_rad_per_count();
  DriveAxisConfig pan;
  pan.name = "pan";
  pan.unit_id = 1;
  pan.registers = default_register_map(pan_rated_torque_nm, pan_rad_per_count);
  pan.safety.configured_max_torque_nm = 5.73;
  pan.safety.motor_max_torque_nm = 5.73;
  set_envelope_model(pan.safety, pan_plant_config());
  DriveAxisConfig tilt;
  tilt.name = "tilt";
  tilt.unit_id = 2;
  tilt.registers = default_register_map(tilt_rated_torque_nm, tilt_rad_per_count);
  tilt.safety.configured_max_torque_nm = 0.9555;
  tilt.safety.motor_max_torque_nm = 0.9555;
  tilt.safety.brake_gain_nm_s_per_rad = 0.01;
  set_envelope_model(tilt.safety, tilt_plant_config());
  c.axes = {pan, tilt};
  return c;
}

DriveClient::DriveClient(DriveClientConfig config) : config_(std::move(config)), rtt_us_(8192) {
  if (config_.axes.empty()) throw ConfigError("servo_drive: no axes configured");
  if (!(config_.cycle_rate_hz > 0)) throw ConfigError("servo_drive: cycle_rate_hz must be > 0");
  if (config_.fault_clear_stable_cycles < 1) {
    throw ConfigError("servo_drive: fault_clear_stable_cycles must be >= 1");
  }
  const double period_s = 1.0 / config_.cycle_rate_hz;
  if (!(config_.response_timeout_s > 0) ||
      (config_.require_timeout_within_period &&
       config_.response_timeout_s * static_cast<double>(config_.axes.size()) >= period_s)) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "servo_drive: response_timeout_s %.6f x %zu axes does not fit in the %.6f s "
                  "period: a silent amplifier would overrun the cycle",
                  config_.response_timeout_s, config_.axes.size(), period_s);
    throw ConfigError(msg);
  }
  int max_write = 0;
  int max_read = 0;
  bool single_run = true;
  for (const DriveAxisConfig& axis : config_.axes) {
    try {
      validate(axis.registers);
    } catch (const std::invalid_argument& e) {
      throw ConfigError("servo_drive: " + axis_label(axis) + ": " + e.what());
    }
    AxisRuntime rt;
    rt.latch = FaultLatch(config_.fault_clear_stable_cycles);
    // Contiguous runs of the cyclically written registers.
    std::vector<const RegisterSpec*> writes;
    for (Signal s : cyclic_writes) {
      if (axis.registers.has(s)) writes.push_back(&axis.registers[s]);
    }
    std::sort(writes.begin(), writes.end(),
              [](const RegisterSpec* a, const RegisterSpec* b) { return a->address < b->address; });
    for (const RegisterSpec* w : writes) {
      if (!rt.write_runs.empty() &&
          rt.write_runs.back().address + rt.write_runs.back().count == w->address) {
        rt.write_runs.back().count += w->width_registers;
      } else {
        rt.write_runs.push_back({w->address, w->width_registers});
      }
    }
    // One read span over the cyclically read registers.
    int lo = 0x10000;
    int hi = 0;
    for (Signal s : cyclic_reads) {
      if (!axis.registers.has(s)) continue;
      lo = std::min<int>(lo, axis.registers[s].address);
      hi = std::max<int>(hi, axis.registers[s].address + axis.registers[s].width_registers);
    }
    if (hi - lo > MODBUS_MAX_WR_READ_REGISTERS) {
      throw ConfigError("servo_drive: " + axis_label(axis) + ": cyclic read span " +
                        std::to_string(hi - lo) + " registers exceeds " +
                        std::to_string(MODBUS_MAX_WR_READ_REGISTERS));
    }
    rt.read_address = static_cast<std::uint16_t>(lo);
    rt.read_count = static_cast<std::uint16_t>(hi - lo);
    int write_count = 0;
    for (const WriteRun& r : rt.write_runs) write_count += r.count;
    max_write = std::max(max_write, write_count);
    max_read = std::max<int>(max_read, rt.read_count);
    single_run = single_run && rt.write_runs.size() == 1;
    axes_.push_back(rt);
  }
  if (config_.transport == Transport::rtu) {
    const ExchangeShape shape{max_write, max_read, config_.use_write_read_0x17 && single_run};
    const std::string refusal =
        check_rtu_cycle_rate(config_.rtu.line, shape, static_cast<int>(config_.axes.size()),
                             config_.rtu.drive_turnaround_s, config_.cycle_rate_hz);
    if (!refusal.empty()) throw ConfigError(refusal);
  }
  command_nm_.assign(config_.axes.size(), 0.0);
  command_snapshot_.assign(config_.axes.size(), 0.0);
  backoff_s_ = config_.reconnect_backoff_initial_s;
}

DriveClient::~DriveClient() {
  try {
    disconnect();
  } catch (...) {  // destructors never throw; disconnect is best effort anyway
  }
}

void DriveClient::open_link() {
  ModbusContext ctx;
  if (config_.transport == Transport::tcp) {
    ctx = make_tcp_context(config_.tcp.host, config_.tcp.port);
  } else {
    const RtuLinkConfig& r = config_.rtu;
    ctx =
        make_rtu_context(r.device, r.line.baud, r.line.parity, r.line.data_bits, r.line.stop_bits);
  }
  set_response_timeout(ctx.get(), configure_timeout_s());
  const std::string peer = config_.transport == Transport::tcp
                               ? config_.tcp.host + ":" + std::to_string(config_.tcp.port)
                               : config_.rtu.device;
  check_modbus(modbus_connect(ctx.get()), "servo_drive: connect to " + peer);
  if (config_.transport == Transport::rtu) {
    if (config_.rtu.rs485) {
      check_modbus(modbus_rtu_set_serial_mode(ctx.get(), MODBUS_RTU_RS485),
                   "servo_drive: RS-485 mode on " + peer);
    }
    if (config_.rtu.rts != MODBUS_RTU_RTS_NONE) {
      check_modbus(modbus_rtu_set_rts(ctx.get(), config_.rtu.rts), "servo_drive: RTS on " + peer);
    }
    if (config_.rtu.rts_delay_us >= 0) {
      check_modbus(modbus_rtu_set_rts_delay(ctx.get(), config_.rtu.rts_delay_us),
                   "servo_drive: RTS delay on " + peer);
    }
    modbus_flush(ctx.get());  // drop anything a drive sent after an earlier timeout
  }
  ctx_ = std::move(ctx);
}

void DriveClient::configure_axes() {
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    const DriveAxisConfig& axis = config_.axes[i];
    const RegisterMap& map = axis.registers;
    const std::string label = "servo_drive: " + axis_label(axis);
    check_modbus(modbus_set_slave(ctx_.get(), axis.unit_id), label + ": set unit id");
    if (map.has(Signal::word_order_probe)) {
      const RegisterSpec& probe = map[Signal::word_order_probe];
      std::uint16_t regs[2] = {0, 0};
      configure_read(axis, probe.address, std::span(regs, probe.width_registers),
                     label + ": read word_order_probe");
      const auto value = static_cast<std::uint32_t>(read_counts(probe, regs));
      if (value != word_order_probe_value) {
        char msg[256];
        std::snprintf(msg, sizeof msg,
                      "%s: word_order_probe reads 0x%08X, expected 0x%08X: the configured "
                      "word_order (%s) does not match the drive",
                      label.c_str(), value, word_order_probe_value,
                      std::string(to_string(probe.word_order)).c_str());
        throw ConfigError(msg);
      }
    }
    // Torque off and disabled before anything else (ros2_control #674: no stale commands).
    if (map.has(Signal::target_torque)) {
      const std::uint16_t zero = 0;
      configure_write(axis, map[Signal::target_torque].address, std::span(&zero, 1),
                      label + ": write target_torque 0");
    }
    if (map.has(Signal::mode_of_operation)) {
      const auto mode = static_cast<std::uint16_t>(axis.mode_of_operation);
      configure_write(axis, map[Signal::mode_of_operation].address, std::span(&mode, 1),
                      label + ": write mode_of_operation");
    }
    if (map.has(Signal::max_torque)) {
      // Drive-side limit = the host's limit: it still holds if the host is wrong.
      const RegisterSpec& spec = map[Signal::max_torque];
      const double limit =
          std::min(axis.safety.configured_max_torque_nm, axis.safety.motor_max_torque_nm);
      std::uint16_t regs[2] = {0, 0};
      write_counts(spec, to_counts(spec, limit), regs);
      configure_write(axis, spec.address, std::span(regs, spec.width_registers),
                      label + ": write max_torque");
    }
    if (map.has(Signal::echo_counter)) {
      std::uint16_t echo = 0;
      configure_read(axis, map[Signal::echo_counter].address, std::span(&echo, 1),
                     label + ": read echo_counter");
      axes_[i].counter = echo;
    }
  }
}

void DriveClient::configure_read(const DriveAxisConfig& axis, std::uint16_t address,
                                 std::span<std::uint16_t> registers, const std::string& what) {
  if (config_.transport == Transport::tcp) {
    std::string message;
    if (tcp_transaction(
            static_cast<std::uint8_t>(axis.unit_id),
            read_registers_request(address, static_cast<std::uint16_t>(registers.size())),
            registers, message, configure_timeout_s()) != ExchangeError::none) {
      throw ModbusError(what + ": " + message);
    }
    return;
  }
  // RTU: libmodbus checks the slave address, CRC, function and byte count itself.
  check_modbus(modbus_read_registers(ctx_.get(), address, static_cast<int>(registers.size()),
                                     registers.data()),
               what);
}

void DriveClient::configure_write(const DriveAxisConfig& axis, std::uint16_t address,
                                  std::span<const std::uint16_t> values, const std::string& what) {
  if (config_.transport == Transport::tcp) {
    std::string message;
    if (tcp_transaction(static_cast<std::uint8_t>(axis.unit_id),
                        write_registers_request(address, values), {}, message,
                        configure_timeout_s()) != ExchangeError::none) {
      throw ModbusError(what + ": " + message);
    }
    return;
  }
  check_modbus(
      modbus_write_registers(ctx_.get(), address, static_cast<int>(values.size()), values.data()),
      what);
}

void DriveClient::connect() {
  close_link();
  open_link();
  try {
    configure_axes();
    set_response_timeout(ctx_.get(), config_.response_timeout_s);  // cyclic budget from now on
  } catch (...) {
    close_link();
    throw;
  }
}

void DriveClient::close_link() {
  ctx_.reset();
  late_reply_due_ = false;  // a fresh connection carries no reply of the old one
  for (AxisRuntime& rt : axes_) rt.missed_in_a_row = 0;
}

void DriveClient::disconnect() {
  if (!ctx_) return;
  for (const DriveAxisConfig& axis : config_.axes) {
    modbus_set_slave(ctx_.get(), axis.unit_id);
    if (axis.registers.has(Signal::target_torque)) {
      modbus_write_register(ctx_.get(), axis.registers[Signal::target_torque].address, 0);
    }
    modbus_write_register(ctx_.get(), axis.registers[Signal::controlword].address,
                          controlword::disable_voltage);
  }
  close_link();
}

void DriveClient::activate(double now_s) {
  std::lock_guard lock(command_mutex_);
  want_enabled_ = true;
  accept_after_s_ = now_s;
  std::fill(command_nm_.begin(), command_nm_.end(), 0.0);
  command_stamp_s_ = std::numeric_limits<double>::quiet_NaN();
  command_arrival_s_ = std::numeric_limits<double>::quiet_NaN();
}

void DriveClient::deactivate() {
  std::lock_guard lock(command_mutex_);
  want_enabled_ = false;
}

void DriveClient::request_fault_reset() {
  std::lock_guard lock(command_mutex_);
  fault_reset_requested_ = true;
}

void DriveClient::set_estop(bool active, double now_s) {
  std::lock_guard lock(command_mutex_);
  if (estop_ && !active) {
    accept_after_s_ = now_s;
    command_stamp_s_ = std::numeric_limits<double>::quiet_NaN();
    command_arrival_s_ = std::numeric_limits<double>::quiet_NaN();
  }
  estop_ = active;
}

bool DriveClient::set_command(const std::vector<double>& torque_nm, double stamp_s,
                              double arrival_s) {
  std::lock_guard lock(command_mutex_);
  if (stamp_s < accept_after_s_) {  // from before activation / e-stop release
    ++command_stats_.before_activation;
    return false;
  }
  // A stamp from the future would stay "fresh" until our clock caught up with it (issue 20
  // 1.1): refuse it; the previous command keeps ageing as before.
  if (is_future_stamped(config_.command_freshness, stamp_s, arrival_s) || !std::isfinite(stamp_s)) {
    ++command_stats_.future_stamped;
    command_stats_.last_future_ahead_s = stamp_s - arrival_s;
    return false;
  }
  const std::size_t n = std::min(torque_nm.size(), command_nm_.size());
  std::copy_n(torque_nm.begin(), n, command_nm_.begin());
  std::fill(command_nm_.begin() + static_cast<std::ptrdiff_t>(n), command_nm_.end(), 0.0);
  command_stamp_s_ = stamp_s;
  command_arrival_s_ = arrival_s;
  ++command_stats_.accepted;
  return true;
}

void DriveClient::retune(const DriveLiveSettings& live) {
  if (live.safety.size() != config_.axes.size()) {
    throw ConfigError("servo_drive: " + std::to_string(live.safety.size()) +
                      " axes of safety settings for " + std::to_string(config_.axes.size()) +
                      " axes");
  }
  for (std::size_t i = 0; i < live.safety.size(); ++i) {
    if (!(live.safety[i].soft_lower_rad < live.safety[i].soft_upper_rad)) {
      throw ConfigError("servo_drive: axis " + config_.axes[i].name +
                        ": soft_lower_rad must be below soft_upper_rad");
    }
  }
  std::lock_guard lock(command_mutex_);
  retuned_ = live;
}

CommandStatistics DriveClient::command_statistics() const {
  std::lock_guard lock(command_mutex_);
  return command_stats_;
}

LinkStatistics DriveClient::statistics() const {
  std::lock_guard lock(command_mutex_);
  LinkStatistics s = stats_;
  s.rtt_us_p50 = rtt_us_.percentile(50);
  s.rtt_us_p99 = rtt_us_.percentile(99);
  return s;
}

std::uint16_t DriveClient::next_controlword(std::size_t axis, bool want_enabled, bool estop,
                                            bool reset) {
  AxisRuntime& rt = axes_[axis];
  const DriveState state =
      rt.last.valid || rt.last.statusword != 0 ? rt.last.state : DriveState::not_ready_to_switch_on;
  if (state == DriveState::fault) {
    if (!reset) return controlword::disable_voltage;
    // Fault reset acts on the 0 -> 1 edge of bit 7: low one cycle, high the next.
    const std::uint16_t cw = rt.reset_phase == 0 ? 0 : controlword::fault_reset_bit;
    rt.reset_phase ^= 1;
    return cw;
  }
  rt.reset_phase = 0;
  const bool powered = state == DriveState::operation_enabled || state == DriveState::switched_on;
  if (estop) {
    if (config_.estop_action == EstopAction::quick_stop && state == DriveState::operation_enabled) {
      return controlword::quick_stop;
    }
    return powered ? controlword::switch_on : controlword::disable_voltage;
  }
  if (!want_enabled) {
    if (powered) return controlword::switch_on;  // disable operation: Switched on, no torque
    if (state == DriveState::ready_to_switch_on) return controlword::shutdown;
    return controlword::disable_voltage;
  }
  switch (state) {
    case DriveState::switch_on_disabled:
      return controlword::shutdown;
    case DriveState::ready_to_switch_on:
      return controlword::switch_on;
    case DriveState::switched_on:
    case DriveState::operation_enabled:
    case DriveState::quick_stop_active:
      return controlword::enable_operation;
    default:
      return controlword::disable_voltage;
  }
}

DriveClient::ExchangeError DriveClient::classify_modbus_errno(int err) {
  if (err == ETIMEDOUT) return ExchangeError::timeout;
  if (err > MODBUS_ENOBASE && err < MODBUS_ENOBASE + 12) return ExchangeError::exception;
  // A reply that does not answer the request: another slave, bad CRC, data or length.
  if (err == EMBBADSLAVE || err == EMBBADCRC || err == EMBBADDATA || err == EMBMDATA ||
      err == EMBBADEXC) {
    return ExchangeError::bad_reply;
  }
  return ExchangeError::io;
}

DriveClient::ExchangeError DriveClient::tcp_transaction(std::uint8_t unit_id,
                                                        const RequestPdu& request,
                                                        std::span<std::uint16_t> registers,
                                                        std::string& message, double timeout_s) {
  const int fd = modbus_get_socket(ctx_.get());
  transaction_id_ = static_cast<std::uint16_t>(transaction_id_ + 1);
  const FrameBytes adu = encode_tcp_request(transaction_id_, unit_id, request);
  for (std::size_t sent = 0; sent < adu.size();) {
    const ssize_t n = ::send(fd, adu.data() + sent, adu.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      message = std::string("send: ") + std::strerror(errno);
      return ExchangeError::io;
    }
    sent += static_cast<std::size_t>(n);
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(timeout_s));
  auto failed = [&](ReadResult r) {
    message = r == ReadResult::timeout ? "Connection timed out" : "connection closed by the peer";
    return r == ReadResult::timeout ? ExchangeError::timeout : ExchangeError::io;
  };
  std::uint8_t header[mbap_header_bytes];
  if (const ReadResult r = read_exact(fd, header, deadline); r != ReadResult::ok) return failed(r);
  // The reply to the request that missed its timeout last cycle may come first (a TCP server
  // answers in order): read it whole and drop it, then this request's (issue 16 section 3).
  if (late_reply_due_) {
    late_reply_due_ = false;  // it comes now or, once a newer reply came, never
    if (((header[0] << 8) | header[1]) == late_transaction_id_) {
      const std::size_t length = static_cast<std::size_t>((header[4] << 8) | header[5]);
      std::array<std::uint8_t, max_pdu_bytes> dropped;
      if (length < 2 || length - 1 > dropped.size()) {
        message = "bad reply: a late reply of MBAP length " + std::to_string(length);
        return ExchangeError::bad_reply;
      }
      const std::span<std::uint8_t> rest(dropped.data(), length - 1);
      if (const ReadResult r = read_exact(fd, rest, deadline); r != ReadResult::ok) {
        return failed(r);
      }
      {
        std::lock_guard lock(command_mutex_);
        ++stats_.late_replies;
      }
      // ACK it now: a server that keeps Nagle's algorithm on holds the reply to this request,
      // sent right behind the late one, until the late one is acknowledged (Linux delays ACKs
      // by up to 40 ms). Best effort.
      const int one = 1;
      (void)::setsockopt(fd, IPPROTO_TCP, TCP_QUICKACK, &one, sizeof one);
      if (const ReadResult r = read_exact(fd, header, deadline); r != ReadResult::ok) {
        return failed(r);
      }
    }
  }
  std::size_t pdu_bytes = 0;
  ReplyCheck check = check_tcp_reply_header(header, transaction_id_, unit_id, request, pdu_bytes);
  if (check.ok()) {
    // Inline: no allocation per exchange. The header check allows only the lengths of the
    // asked reply or an exception, both within a PDU's 253 bytes.
    std::array<std::uint8_t, max_pdu_bytes> buffer;
    if (pdu_bytes > buffer.size()) {
      message = "bad reply: PDU of " + std::to_string(pdu_bytes) + " bytes";
      return ExchangeError::bad_reply;
    }
    const std::span<std::uint8_t> pdu(buffer.data(), pdu_bytes);
    if (const ReadResult r = read_exact(fd, pdu, deadline); r != ReadResult::ok) return failed(r);
    check = check_reply_pdu(pdu, request, registers);
  }
  if (check.ok()) return ExchangeError::none;
  if (check.problem == ReplyProblem::exception) {
    message = check.message;
    return ExchangeError::exception;
  }
  message = "bad reply: " + check.message;
  return ExchangeError::bad_reply;
}

DriveClient::ExchangeError DriveClient::exchange(std::size_t axis, std::uint16_t cw,
                                                 double torque_nm, AxisFeedback& fb,
                                                 std::string& message) {
  AxisRuntime& rt = axes_[axis];
  const DriveAxisConfig& cfg = config_.axes[axis];
  const RegisterMap& map = cfg.registers;
  rt.counter = static_cast<std::uint16_t>(rt.counter + 1);

  // Register image of the writes: controlword, torque, heartbeat counter.
  std::uint16_t image[MODBUS_MAX_WR_WRITE_REGISTERS] = {};
  const std::uint16_t base = rt.write_runs.front().address;
  auto put = [&](Signal s, std::int64_t counts) {
    if (!map.has(s)) return;
    const RegisterSpec& spec = map[s];
    write_counts(spec, counts, std::span(image + (spec.address - base), spec.width_registers));
  };
  const WriteRun& last_run = rt.write_runs.back();
  if (last_run.address + last_run.count - base > MODBUS_MAX_WR_WRITE_REGISTERS) {
    message = "write registers too far apart";
    return ExchangeError::io;
  }
  put(Signal::controlword, cw);
  put(Signal::target_torque, to_counts(map[Signal::target_torque], torque_nm));
  put(Signal::host_counter, rt.counter);

  std::uint16_t regs[MODBUS_MAX_WR_READ_REGISTERS] = {};
  const double t0 = monotonic_us();
  const bool one_transaction = config_.use_write_read_0x17 && rt.write_runs.size() == 1;
  ExchangeError error = ExchangeError::none;
  if (config_.transport == Transport::tcp) {
    // Our own framing, so that every reply is checked (unit id, length, ...) before use.
    const auto unit = static_cast<std::uint8_t>(cfg.unit_id);
    if (one_transaction) {
      error = tcp_transaction(
          unit,
          write_read_registers_request(base, std::span(image, rt.write_runs.front().count),
                                       rt.read_address, rt.read_count),
          regs, message, config_.response_timeout_s);
    } else {
      for (const WriteRun& run : rt.write_runs) {
        if (error != ExchangeError::none) break;
        error =
            tcp_transaction(unit,
                            write_registers_request(
                                run.address, std::span(image + (run.address - base), run.count)),
                            {}, message, config_.response_timeout_s);
      }
      if (error == ExchangeError::none) {
        error = tcp_transaction(unit, read_registers_request(rt.read_address, rt.read_count), regs,
                                message, config_.response_timeout_s);
      }
    }
  } else {
    // RTU: libmodbus checks the slave address, CRC, function and byte count itself.
    int rc = modbus_set_slave(ctx_.get(), cfg.unit_id);
    if (rc != -1 && one_transaction) {
      rc = modbus_write_and_read_registers(ctx_.get(), base, rt.write_runs.front().count, image,
                                           rt.read_address, rt.read_count, regs);
    } else {
      for (const WriteRun& run : rt.write_runs) {
        if (rc == -1) break;
        rc = modbus_write_registers(ctx_.get(), run.address, run.count,
                                    image + (run.address - base));
      }
      if (rc != -1) rc = modbus_read_registers(ctx_.get(), rt.read_address, rt.read_count, regs);
    }
    if (rc == -1) {
      const int err = errno;
      message = modbus_strerror(err);
      error = classify_modbus_errno(err);
      if (error == ExchangeError::bad_reply) message = "bad reply: " + message;
    }
  }
  const double rtt_us = monotonic_us() - t0;
  if (error != ExchangeError::none) {
    message = axis_label(cfg) + ": " + message;
    return error;
  }
  auto get = [&](Signal s) {
    const RegisterSpec& spec = map[s];
    return read_counts(spec, std::span<const std::uint16_t>(regs + (spec.address - rt.read_address),
                                                            spec.width_registers));
  };
  // Stale-reply check: the drive must echo this cycle's counter (reference 1.4: RTU silently
  // returns replies to older requests after a timeout).
  if (map.has(Signal::echo_counter) && map.has(Signal::host_counter)) {
    const auto echo = static_cast<std::uint16_t>(get(Signal::echo_counter));
    if (echo != rt.counter) {
      message = axis_label(cfg) + ": stale reply (echo " + std::to_string(echo) + ", expected " +
                std::to_string(rt.counter) + ")";
      return ExchangeError::stale;
    }
  }
  fb.valid = true;
  fb.statusword = static_cast<std::uint16_t>(get(Signal::statusword));
  fb.state = decode_statusword(fb.statusword);
  fb.q_rad = to_si(map[Signal::position_actual], get(Signal::position_actual));
  fb.qd_rad_s = to_si(map[Signal::velocity_actual], get(Signal::velocity_actual));
  if (map.has(Signal::torque_actual)) {
    fb.torque_actual_nm = to_si(map[Signal::torque_actual], get(Signal::torque_actual));
  }
  if (map.has(Signal::error_code))
    fb.error_code = static_cast<std::uint16_t>(get(Signal::error_code));
  {
    std::lock_guard lock(command_mutex_);
    ++stats_.exchanges;
    rtt_us_.add(rtt_us);
  }
  return ExchangeError::none;
}

void DriveClient::on_link_fault(double now_s, ExchangeError error, const std::string& message) {
  {
    std::lock_guard lock(command_mutex_);
    switch (error) {
      case ExchangeError::timeout:
        ++stats_.timeouts;
        break;
      case ExchangeError::exception:
        ++stats_.exceptions;
        break;
      case ExchangeError::stale:
        ++stats_.stale_replies;
        break;
      case ExchangeError::bad_reply:
        ++stats_.bad_replies;
        break;
      default:
        ++stats_.errors;
        break;
    }
  }
  // Best effort torque 0 while the link may still carry it (not after a timeout: the drive's
  // own watchdog covers that, and another timeout would overrun the cycle).
  if (error == ExchangeError::stale || error == ExchangeError::exception ||
      error == ExchangeError::bad_reply) {
    for (const DriveAxisConfig& axis : config_.axes) {
      modbus_set_slave(ctx_.get(), axis.unit_id);
      modbus_write_register(ctx_.get(), axis.registers[Signal::target_torque].address, 0);
    }
  }
  // TCP stays stuck on transaction-id mismatches after a late reply and RTU lags silently
  // (reference 1.4): only a fresh connection / flushed port is trusted again.
  close_link();
  had_fault_ = true;
  next_connect_s_ = now_s + backoff_s_;
  backoff_s_ = std::min(backoff_s_ * 2, config_.reconnect_backoff_max_s);
  for (AxisRuntime& rt : axes_) rt.last.valid = false;
  (void)message;
}

CycleResult DriveClient::cycle(double now_s) {
  CycleResult result;
  cycle(now_s, result);
  return result;
}

void DriveClient::cycle(double now_s, CycleResult& result) {
  result.link_ok = false;
  result.link_fault = false;
  result.fault_message.clear();
  result.axes.assign(axes_.size(), AxisFeedback{});
  // Snapshot of the commands.
  std::vector<double>& command = command_snapshot_;
  double stamp = 0;
  double arrival = 0;
  bool want_enabled = false;
  bool estop = false;
  bool reset = false;
  {
    std::lock_guard lock(command_mutex_);
    if (retuned_) {
      // Under the command mutex: set_command() reads command_freshness under it too.
      config_.command_freshness = retuned_->command_freshness;
      config_.estop_action = retuned_->estop_action;
      config_.auto_fault_reset = retuned_->auto_fault_reset;
      for (std::size_t i = 0; i < config_.axes.size(); ++i) {
        AxisSafetyConfig& axis = config_.axes[i].safety;
        const AxisSafetyConfig& next = retuned_->safety[i];
        axis.soft_lower_rad = next.soft_lower_rad;
        axis.soft_upper_rad = next.soft_upper_rad;
        axis.brake_zone_rad = next.brake_zone_rad;
        axis.brake_gain_nm_s_per_rad = next.brake_gain_nm_s_per_rad;
        axis.envelope_brake_fraction = next.envelope_brake_fraction;
      }
      retuned_.reset();
    }
    std::copy(command_nm_.begin(), command_nm_.end(), command.begin());
    stamp = command_stamp_s_;
    arrival = command_arrival_s_;
    want_enabled = want_enabled_;
    estop = estop_;
    reset = fault_reset_requested_ || config_.auto_fault_reset;
  }
  if (!fatal_error_.empty()) {
    result.link_fault = true;
    result.fault_message = fatal_error_;
    for (auto& fb : result.axes) fb.safety_reasons = safety_link_fault;
    return;
  }
  if (!ctx_) {
    result.link_fault = true;
    for (auto& fb : result.axes) fb.safety_reasons = safety_link_fault;
    if (now_s < next_connect_s_) {
      result.fault_message = "servo_drive: link down, reconnecting";
      return;
    }
    try {
      connect();
    } catch (const ConfigError& e) {
      fatal_error_ = e.what();
      result.fault_message = fatal_error_;
      return;
    } catch (const std::exception& e) {
      std::lock_guard lock(command_mutex_);
      ++stats_.connect_failures;
      next_connect_s_ = now_s + backoff_s_;
      backoff_s_ = std::min(backoff_s_ * 2, config_.reconnect_backoff_max_s);
      result.fault_message = e.what();
      return;
    }
    if (had_fault_) {
      std::lock_guard lock(command_mutex_);
      ++stats_.reconnects;
    }
  }

  bool any_fault_state = false;
  bool all_exchanged = true;
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    AxisRuntime& rt = axes_[i];
    const DriveAxisConfig& cfg = config_.axes[i];
    SafetyInput in;
    in.command_nm = command[i];
    in.command_stamp_s = stamp;
    in.command_arrival_s = arrival;
    in.now_s = now_s;
    in.estop = estop;
    in.link_healthy = true;
    in.drive_enabled =
        want_enabled && rt.last.valid && rt.last.state == DriveState::operation_enabled;
    in.fault_latched = rt.latch.latched();
    in.feedback_valid = rt.last.valid;
    in.q_rad = rt.last.q_rad;
    in.qd_rad_s = rt.last.qd_rad_s;
    // The feedback was read one exchange ago; the torque written then acts until this one
    // lands, and this one holds for a period (the velocity envelope needs both).
    in.previous_torque_nm = rt.last.commanded_torque_nm;
    in.feedback_age_s = rt.last.valid ? std::max(0.0, now_s - rt.last_time_s) : 0.0;
    in.command_hold_s = 1.0 / config_.cycle_rate_hz;
    const SafetyOutput safe = apply_safety(cfg.safety, config_.command_freshness, in);
    const std::uint16_t cw = next_controlword(i, want_enabled, estop, reset);

    AxisFeedback fb;
    std::string message;
    const ExchangeError error = exchange(i, cw, safe.torque_nm, fb, message);
    // One late reply is a missed cycle, not a link fault (issue 16 section 3): on an ordinary
    // host a reply now and then misses a sub-millisecond timeout, and a cut to zero torque and
    // a reconnect each time is a torque dropout every 100 ms. The drive keeps the torque last
    // written for this period (its own watchdog still removes it if the host stays away); the
    // next cycle's safety rules see feedback one period older. No valid reply for 2 periods,
    // or a miss while an earlier late reply is still due, is a link fault as before. TCP only:
    // over RTU libmodbus cannot tell a late reply from the next one.
    if (error == ExchangeError::timeout && config_.transport == Transport::tcp &&
        rt.missed_in_a_row == 0 && !late_reply_due_) {
      late_reply_due_ = true;
      late_transaction_id_ = transaction_id_;
      ++rt.missed_in_a_row;
      {
        std::lock_guard lock(command_mutex_);
        ++stats_.timeouts;
        ++stats_.missed_cycles;
      }
      AxisFeedback missed = rt.last;
      missed.valid = false;
      missed.commanded_torque_nm = safe.torque_nm;
      missed.controlword = cw;
      missed.safety_reasons = safe.reasons;
      missed.fault_latched = rt.latch.latched();
      result.axes[i] = missed;
      all_exchanged = false;
      continue;
    }
    if (error != ExchangeError::none) {
      on_link_fault(now_s, error, message);
      result.link_fault = true;
      result.fault_message = "servo_drive: " + message;
      for (auto& f : result.axes) {
        f = AxisFeedback{};
        f.safety_reasons = safety_link_fault;
      }
      return;
    }
    rt.missed_in_a_row = 0;
    fb.commanded_torque_nm = safe.torque_nm;
    fb.controlword = cw;
    fb.safety_reasons = safe.reasons;
    fb.fault_latched = rt.latch.update(fb.state, reset);
    rt.last = fb;
    rt.last_time_s = now_s;
    result.axes[i] = fb;
    if (fb.state == DriveState::fault || fb.state == DriveState::fault_reaction_active) {
      any_fault_state = true;
      if (result.fault_message.empty()) {
        char msg[128];
        std::snprintf(msg, sizeof msg, "servo_drive: %s: drive fault, error code 0x%04X",
                      axis_label(cfg).c_str(), fb.error_code);
        result.fault_message = msg;
      }
    } else if (fb.fault_latched && result.fault_message.empty()) {
      result.fault_message = "servo_drive: " + axis_label(cfg) +
                             ": fault latched, zero torque until a fault reset request and " +
                             std::to_string(config_.fault_clear_stable_cycles) +
                             " cycles of Operation enabled";
    }
  }
  backoff_s_ = config_.reconnect_backoff_initial_s;
  result.link_ok = all_exchanged;
  if (!any_fault_state) {
    std::lock_guard lock(command_mutex_);
    fault_reset_requested_ = false;
  }
}

}  // namespace avs::servo
