// The DLPC350 emulator (dlpc350_emulator.hpp).
#include "avs/projector/dlpc350_emulator.hpp"

namespace avs::projector {

namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint32_t u32_at(const Bytes& d, std::size_t i) {
  return d[i] | d[i + 1] << 8 | d[i + 2] << 16 | static_cast<std::uint32_t>(d[i + 3]) << 24;
}

/// Shortest exposure per bit depth 1..8 in pattern mode (programmer's guide, pattern
/// exposure table), microseconds.
constexpr std::uint32_t kMinExposureUs[] = {235, 700, 1570, 1700, 2000, 2500, 4500, 8333};
constexpr std::uint32_t kBlackFillUs = 230;
/// The data bytes each fixed-size write takes (the programmer's guide's command table).
std::optional<std::size_t> write_length(Command c) {
  switch (c) {
    case Command::kValidate:
    case Command::kDisplayMode:
    case Command::kPatternSource:
    case Command::kPatternTriggerMode:
    case Command::kPatternStartStop:
    case Command::kMailboxAddress:
    case Command::kMailboxControl:
      return 1;
    case Command::kTriggerOut2:
      return 2;
    case Command::kTriggerOut1:
      return 3;
    case Command::kPatternConfig:
      return 4;
    case Command::kExposureFramePeriod:
      return 8;
    default:
      return std::nullopt;
  }
}

}  // namespace

Dlpc350Emulator::Dlpc350Emulator(EmulatorConfig config) : config_(config) {}

void Dlpc350Emulator::unplug() {
  std::lock_guard lock(mutex_);
  plugged_ = false;
  ++generation_;
  replies_.clear();
  partial_.clear();
  late_reply_.reset();
}

void Dlpc350Emulator::plug_in() {
  std::lock_guard lock(mutex_);
  plugged_ = true;
  ++generation_;
  state_ = State{};
}

bool Dlpc350Emulator::plugged_in() const {
  std::lock_guard lock(mutex_);
  return plugged_;
}

void Dlpc350Emulator::drop_replies(int n) {
  std::lock_guard lock(mutex_);
  drop_replies_ += n;
}

void Dlpc350Emulator::delay_next_reply() {
  std::lock_guard lock(mutex_);
  delay_next_ = true;
}

std::optional<std::uint64_t> Dlpc350Emulator::open_generation() const {
  std::lock_guard lock(mutex_);
  if (!plugged_) return std::nullopt;
  return generation_;
}

IoResult Dlpc350Emulator::write(const Report& report, std::uint64_t generation) {
  std::lock_guard lock(mutex_);
  if (!plugged_ || generation != generation_) return IoResult::kDisconnected;
  received_.push_back(report);
  partial_.push_back(report);
  const std::size_t needed = request_report_count(partial_.front());
  if (needed == 0) {  // a length no request has: the controller drops the report
    partial_.clear();
    return IoResult::kOk;
  }
  if (partial_.size() < needed) return IoResult::kOk;
  DecodedRequest decoded = decode_request(partial_);
  partial_.clear();
  if (decoded.request) handle(*decoded.request);
  return IoResult::kOk;
}

IoResult Dlpc350Emulator::read(Report& report, std::uint64_t generation) {
  std::lock_guard lock(mutex_);
  if (!plugged_ || generation != generation_) return IoResult::kDisconnected;
  if (replies_.empty()) return IoResult::kTimeout;
  report = replies_.front();
  replies_.pop_front();
  return IoResult::kOk;
}

void Dlpc350Emulator::reply(const Request& r, bool nack, Bytes data) {
  if (!r.reply_wanted && !nack) return;
  if (drop_replies_ > 0) {
    --drop_replies_;
    return;
  }
  const Report report = encode_reply({nack, r.sequence, std::move(data)});
  if (delay_next_) {
    delay_next_ = false;
    late_reply_ = report;
    return;
  }
  if (late_reply_) {
    replies_.push_back(*late_reply_);
    late_reply_.reset();
  }
  replies_.push_back(report);
}

void Dlpc350Emulator::handle(const Request& r) {
  ++commands_;
  std::optional<Bytes> answer = r.access == Access::kWrite ? handle_write(r) : handle_read(r);
  reply(r, !answer.has_value(), answer.value_or(Bytes{}));
}

std::optional<Bytes> Dlpc350Emulator::handle_write(const Request& r) {
  State& s = state_;
  const Bytes& d = r.data;
  if (r.command == Command::kMailboxData) {
    if (s.running) return std::nullopt;  // the guide: stop the sequence before changing it
    if (s.mailbox == 2) {
      if (d.size() % 3 != 0 || s.mailbox_address + d.size() / 3 > 128) return std::nullopt;
      s.lut.resize(std::max<std::size_t>(s.lut.size(), s.mailbox_address + d.size() / 3));
      for (std::size_t i = 0; i < d.size() / 3; ++i) {
        s.lut[s.mailbox_address + i] = PatternEntry::decode(&d[3 * i]);
      }
    } else if (s.mailbox == 1) {
      // A 2-entry image LUT arrives swapped (image_lut_mailbox_bytes).
      s.images = d.size() == 2 ? Bytes{d[1], d[0]} : d;
    } else {
      return std::nullopt;  // no mailbox open
    }
    s.validated = false;
    return Bytes{};
  }
  const std::optional<std::size_t> length = write_length(r.command);
  if (!length || d.size() != *length) return std::nullopt;
  const bool changes_sequence =
      r.command != Command::kPatternStartStop && r.command != Command::kValidate;
  // The guide: stop the sequence before changing it.
  if (s.running && changes_sequence) return std::nullopt;
  switch (r.command) {
    case Command::kDisplayMode:
      s.pattern_mode = d[0] == 1;
      break;
    case Command::kPatternSource:
      if (d[0] != 0 && d[0] != 3) return std::nullopt;
      s.source = d[0];
      break;
    case Command::kPatternTriggerMode:
      if (d[0] > 4) return std::nullopt;
      s.trigger_mode = d[0];
      break;
    case Command::kExposureFramePeriod:
      s.exposure_us = u32_at(d, 0);
      s.period_us = u32_at(d, 4);
      break;
    case Command::kTriggerOut1:
      std::copy(d.begin(), d.end(), s.trigger_out1.begin());
      break;
    case Command::kTriggerOut2:
      std::copy(d.begin(), d.end(), s.trigger_out2.begin());
      break;
    case Command::kPatternConfig:
      std::copy(d.begin(), d.end(), s.pattern_config.begin());
      break;
    case Command::kMailboxControl:
      if (d[0] > 2) return std::nullopt;  // 3 (variable exposure) is not emulated
      s.mailbox = d[0];
      s.mailbox_address = 0;
      break;
    case Command::kMailboxAddress:
      if (s.mailbox == 0) return std::nullopt;
      s.mailbox_address = d[0];
      break;
    case Command::kValidate:
      s.validation = validate();
      s.validated = true;
      s.busy_reads_left = config_.busy_reads;
      return Bytes{};
    case Command::kPatternStartStop:
      if (d[0] > 2) return std::nullopt;
      if (d[0] == 2) {
        // Only a validated, valid pattern-mode sequence starts.
        if (!s.pattern_mode || !s.validated || (s.validation & 0x03) != 0) return std::nullopt;
        s.running = true;
      } else {
        s.running = false;
      }
      return Bytes{};
    default:
      return std::nullopt;
  }
  s.validated = false;
  return Bytes{};
}

std::optional<Bytes> Dlpc350Emulator::handle_read(const Request& r) {
  State& s = state_;
  if (!r.data.empty()) return std::nullopt;
  switch (r.command) {
    case Command::kHardwareStatus:
      return Bytes{s.hardware_status};
    case Command::kSystemStatus:
      return Bytes{0x01};  // memory test passed
    case Command::kMainStatus:
      return Bytes{static_cast<std::uint8_t>(s.running ? 0x02 : 0x00)};
    case Command::kVersion: {
      // Application 3.0.0, API 3.0.0, SW config 1.0.0, sequence config 1.0.0 (byte 3: major).
      Bytes v(16, 0);
      v[3] = 3;
      v[7] = 3;
      v[11] = 1;
      v[15] = 1;
      return v;
    }
    case Command::kValidate:
      if (s.busy_reads_left > 0) {
        --s.busy_reads_left;
        return Bytes{0x80};
      }
      return Bytes{s.validation};
    case Command::kDisplayMode:
      return Bytes{static_cast<std::uint8_t>(s.pattern_mode ? 1 : 0)};
    case Command::kPatternSource:
      return Bytes{s.source};
    case Command::kPatternTriggerMode:
      return Bytes{s.trigger_mode};
    case Command::kPatternStartStop:
      return Bytes{static_cast<std::uint8_t>(s.running ? 2 : 0)};
    case Command::kExposureFramePeriod: {
      Bytes b;
      for (std::uint32_t v : {s.exposure_us, s.period_us}) {
        for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
      }
      return b;
    }
    case Command::kTriggerOut1:
      return Bytes(s.trigger_out1.begin(), s.trigger_out1.end());
    case Command::kPatternConfig:
      return Bytes(s.pattern_config.begin(), s.pattern_config.end());
    default:
      return std::nullopt;
  }
}

std::uint8_t Dlpc350Emulator::validate() const {
  const State& s = state_;
  std::uint8_t bits = 0;
  const std::size_t entries = static_cast<std::size_t>(s.pattern_config[0]) + 1;
  const std::size_t images = static_cast<std::size_t>(s.pattern_config[3]) + 1;
  // Bit 0: exposure / frame period. Bit 4: a shorter exposure leaves < 230 us.
  int depth = 1;
  for (const PatternEntry& e : s.lut) depth = std::max(depth, e.bit_depth);
  if (s.exposure_us == 0 || s.period_us < s.exposure_us ||
      s.exposure_us < kMinExposureUs[std::clamp(depth, 1, 8) - 1]) {
    bits |= 0x01;
  } else if (s.period_us > s.exposure_us && s.period_us - s.exposure_us < kBlackFillUs) {
    bits |= 0x10;
  }
  // Bit 1: pattern numbers (LUT entries the config counts, planes of the depth, images that
  // are in flash).
  bool numbers_ok = s.lut.size() >= entries && s.images.size() >= images;
  for (std::size_t i = 0; numbers_ok && i < entries; ++i) {
    const PatternEntry& e = s.lut[i];
    numbers_ok = e.bit_depth >= 1 && e.bit_depth <= 8 &&
                 e.pattern_number <= (e.bit_depth == 1 ? 25 : 24 / e.bit_depth - 1);
  }
  for (std::size_t i = 0; numbers_ok && i < images; ++i) {
    numbers_ok = s.images[i] < config_.flash_image_count;
  }
  if (!numbers_ok || s.source != 3) bits |= 0x02;
  // Bits 2, 3: trigger out 1 shared across a black fill; an external trigger after a vector
  // without a black fill.
  for (std::size_t i = 1; i < std::min(entries, s.lut.size()); ++i) {
    const PatternEntry& e = s.lut[i];
    const PatternEntry& prev = s.lut[i - 1];
    if (e.trigger_out_previous && prev.insert_black) bits |= 0x04;
    const bool external =
        e.trigger == TriggerType::kExternalPositive || e.trigger == TriggerType::kExternalNegative;
    if (external && !prev.insert_black) bits |= 0x08;
  }
  return bits;
}

std::vector<Report> Dlpc350Emulator::received() const {
  std::lock_guard lock(mutex_);
  return received_;
}
bool Dlpc350Emulator::running() const {
  std::lock_guard lock(mutex_);
  return state_.running;
}
bool Dlpc350Emulator::pattern_mode() const {
  std::lock_guard lock(mutex_);
  return state_.pattern_mode;
}
std::vector<PatternEntry> Dlpc350Emulator::pattern_lut() const {
  std::lock_guard lock(mutex_);
  return state_.lut;
}
std::vector<std::uint8_t> Dlpc350Emulator::image_lut() const {
  std::lock_guard lock(mutex_);
  return state_.images;
}
std::uint32_t Dlpc350Emulator::exposure_us() const {
  std::lock_guard lock(mutex_);
  return state_.exposure_us;
}
std::uint32_t Dlpc350Emulator::frame_period_us() const {
  std::lock_guard lock(mutex_);
  return state_.period_us;
}
std::array<std::uint8_t, 3> Dlpc350Emulator::trigger_out1() const {
  std::lock_guard lock(mutex_);
  return state_.trigger_out1;
}
std::uint64_t Dlpc350Emulator::commands_handled() const {
  std::lock_guard lock(mutex_);
  return commands_;
}

TransportOpener emulator_opener(std::shared_ptr<Dlpc350Emulator> device) {
  return [device](std::string& why_not) -> std::unique_ptr<HidTransport> {
    const std::optional<std::uint64_t> generation = device->open_generation();
    if (!generation) {
      why_not = "the emulated DLPC350 is unplugged";
      return nullptr;
    }
    return std::make_unique<EmulatorTransport>(device, *generation);
  };
}

}  // namespace avs::projector
