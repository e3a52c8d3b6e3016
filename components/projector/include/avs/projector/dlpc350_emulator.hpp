// An emulator of the DLPC350's USB command protocol, byte for byte: it takes the HID reports a
// host writes, keeps the pattern-mode state (display mode, source, trigger mode, exposure and
// period, trigger out 1, pattern config, the pattern and image LUTs through the mailbox, running
// or not), validates the sequence as the programmer's guide states the rules, and answers with
// ACK/NACK and read replies. Faults on demand: replies lost (a USB read timeout), the device
// unplugged (every open handle dies) and plugged back (power-on state). Used by the tests and
// by the `projector` component with `transport: emulator` (no hardware here).
//
// What it does NOT model (docs/devices.md section 7): timing (replies are there at once, the
// sequencer does not advance), flash contents beyond their count, video mode, variable
// exposure, commands other than those of Command. Rules it applies where the programmer's
// guide gives them; any the real firmware adds are unknown here.
#pragma once

#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "avs/projector/hid_transport.hpp"
#include "avs/projector/pattern_sequence.hpp"

namespace avs::projector {

struct EmulatorConfig {
  int flash_image_count = 1;  ///< 24-bit images in the emulated flash
  int busy_reads = 1;         ///< LUT_VALID reads answered "busy" after a validate write
};

/// The emulated controller (shared by every handle opened on it). Thread-safe.
class Dlpc350Emulator {
 public:
  explicit Dlpc350Emulator(EmulatorConfig config = {});

  // ---- Faults ----
  void unplug();   ///< open handles die; opens fail until plug_in()
  void plug_in();  ///< back in its power-on state (video mode, stopped, LUTs empty)
  bool plugged_in() const;
  /// The next `n` replies are never sent (the host's read times out).
  void drop_replies(int n);
  /// The next reply comes late: not there for the read that waits for it (a timeout), sent
  /// just before the reply to the following request.
  void delay_next_reply();

  // ---- What a host sees (EmulatorTransport calls these) ----
  IoResult write(const Report& report, std::uint64_t generation);
  IoResult read(Report& report, std::uint64_t generation);
  /// The current plug-in generation, or nullopt when unplugged.
  std::optional<std::uint64_t> open_generation() const;

  // ---- State, for tests ----
  std::vector<Report> received() const;  ///< every report written, in order
  bool running() const;
  bool pattern_mode() const;
  std::vector<PatternEntry> pattern_lut() const;
  std::vector<std::uint8_t> image_lut() const;
  std::uint32_t exposure_us() const;
  std::uint32_t frame_period_us() const;
  std::array<std::uint8_t, 3> trigger_out1() const;
  std::uint64_t commands_handled() const;

 private:
  struct State {
    bool pattern_mode = false;
    std::uint8_t source = 0;
    std::uint8_t trigger_mode = 0;
    std::uint32_t exposure_us = 0;
    std::uint32_t period_us = 0;
    std::array<std::uint8_t, 3> trigger_out1{0, 0xBB, 0xBB};
    std::array<std::uint8_t, 2> trigger_out2{0, 0xBB};
    std::array<std::uint8_t, 4> pattern_config{0, 0, 0, 0};
    std::uint8_t mailbox = 0;  ///< 0 closed, 1 image LUT, 2 pattern LUT
    std::uint8_t mailbox_address = 0;
    std::vector<PatternEntry> lut;
    std::vector<std::uint8_t> images;
    std::uint8_t validation = 0;
    bool validated = false;
    int busy_reads_left = 0;
    bool running = false;
    std::uint8_t hardware_status = 0x01;  ///< initialisation done
  };

  void handle(const Request& r);
  std::optional<std::vector<std::uint8_t>> handle_write(const Request& r);
  std::optional<std::vector<std::uint8_t>> handle_read(const Request& r);
  std::uint8_t validate() const;
  void reply(const Request& r, bool nack, std::vector<std::uint8_t> data);

  EmulatorConfig config_;
  mutable std::mutex mutex_;
  bool plugged_ = true;
  std::uint64_t generation_ = 1;
  State state_;
  std::vector<Report> partial_;  ///< reports of a multi-report request so far
  std::deque<Report> replies_;
  int drop_replies_ = 0;
  bool delay_next_ = false;
  std::optional<Report> late_reply_;
  std::vector<Report> received_;
  std::uint64_t commands_ = 0;
};

/// A handle opened on the emulator: dies (kDisconnected) when it is unplugged, like a USB
/// handle, even after it is plugged back in.
class EmulatorTransport final : public HidTransport {
 public:
  EmulatorTransport(std::shared_ptr<Dlpc350Emulator> device, std::uint64_t generation)
      : device_(std::move(device)), generation_(generation) {}
  IoResult write(const Report& report) override { return device_->write(report, generation_); }
  IoResult read(Report& report, std::chrono::milliseconds) override {
    return device_->read(report, generation_);
  }
  std::string description() const override {
    return "DLPC350 emulator (no hardware: avs's byte-exact emulation of the USB protocol)";
  }

 private:
  std::shared_ptr<Dlpc350Emulator> device_;
  std::uint64_t generation_;
};

/// Opens handles on `device` (fails while it is unplugged).
TransportOpener emulator_opener(std::shared_ptr<Dlpc350Emulator> device);

}  // namespace avs::projector
