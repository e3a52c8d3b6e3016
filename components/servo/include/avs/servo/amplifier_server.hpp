// Simulated servo amplifiers behind a Modbus TCP server (libmodbus): one unit id per axis,
// each a SimulatedDrive (CiA 402 + plant + watchdog) serving its register map. Requests are
// handled on the server's I/O thread; drive time advances either by step() from an external
// clock (lockstep simulation, tests) or on the server's own stepping thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avs/servo/modbus_handle.hpp"
#include "avs/servo/simulated_drive.hpp"

namespace avs::servo {

enum class ClockMode : std::uint8_t {
  external,    ///< step(dt) advances every drive (deterministic)
  own_thread,  ///< a thread steps every drive at step_period_s of steady-clock time
};

/// The TCP port of the sim_amplifier component and the one servo_drive connects to unless told
/// otherwise: Modbus's 502 needs root, a test or demo should not.
inline constexpr int sim_amplifier_default_port = 1502;

struct AmplifierServerConfig {
  std::string bind_address = "127.0.0.1";
  int port = 0;  ///< 0: the kernel picks a free port, see AmplifierServer::port()
  std::vector<SimulatedDriveConfig> axes = {pan_drive_config(1), tilt_drive_config(2)};
  ClockMode clock = ClockMode::external;
  double step_period_s = 0.001;  ///< own_thread only
};

struct ServerCounters {
  std::uint64_t requests = 0;
  std::uint64_t replies = 0;
  std::uint64_t dropped_requests = 0;  ///< not answered (silent mode)
  std::uint64_t exceptions = 0;
  std::uint64_t connections_accepted = 0;
};

class AmplifierServer {
 public:
  /// Binds, listens and starts the I/O thread (and the stepping thread in own_thread mode).
  explicit AmplifierServer(AmplifierServerConfig config);
  ~AmplifierServer();
  AmplifierServer(const AmplifierServer&) = delete;
  AmplifierServer& operator=(const AmplifierServer&) = delete;

  int port() const { return port_; }
  std::size_t axis_count() const { return drives_.size(); }

  /// External clock: advances every drive by dt_s. Throws in own_thread mode.
  void step(double dt_s);

  /// Runs `fn` on the drive of `axis` under the server's lock (inspection, set-up).
  void with_drive(std::size_t axis, const std::function<void(SimulatedDrive&)>& fn);
  ServerCounters counters() const;

  // Fault injection.
  void set_reply_delay(double seconds);  ///< every reply is sent this much later
  /// The next `count` replies are sent `seconds` later (a late reply now and then).
  void delay_next_replies(int count, double seconds);
  void drop_connections();               ///< closes every client connection now
  void set_silent(bool silent);          ///< requests are read and never answered
  void set_stalled(bool stalled);        ///< sockets are not read (requests queue up)
  void raise_drive_fault(std::size_t axis, std::uint16_t error_code, bool latched_only = true);

 private:
  void io_loop();
  void step_loop();
  void handle_request(const std::uint8_t* query, int length);
  SimulatedDrive* drive_for_unit(int unit_id);

  AmplifierServerConfig config_;
  ModbusContext ctx_;
  Socket listen_socket_;
  int port_ = 0;
  std::vector<std::unique_ptr<SimulatedDrive>> drives_;
  std::vector<ModbusMapping> mappings_;
  std::vector<Socket> clients_;  ///< I/O thread only

  mutable std::mutex mutex_;  ///< guards drives_, mappings_, counters_
  ServerCounters counters_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> drop_requested_{false};
  std::atomic<bool> silent_{false};
  std::atomic<bool> stalled_{false};
  std::atomic<double> reply_delay_s_{0.0};
  std::atomic<int> delayed_replies_left_{0};
  std::atomic<double> next_replies_delay_s_{0.0};
  std::thread io_thread_;
  std::thread step_thread_;
};

}  // namespace avs::servo
