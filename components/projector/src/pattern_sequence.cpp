// The paper's sequence as DLPC350 LUTs and configuration writes; flash image packing.
#include "avs/projector/pattern_sequence.hpp"

#include <cmath>
#include <stdexcept>

namespace avs::projector {

namespace {

constexpr int kMaxLutEntries = 128;   // pattern LUT entries the controller holds
constexpr int kMaxImageEntries = 64;  // image LUT entries
constexpr double kDelayStepUs = 0.1072;
constexpr int kDelayZeroCode = 0xBB;

Request write(Command c, std::vector<std::uint8_t> data) {
  Request r;
  r.command = c;
  r.access = Access::kWrite;
  r.data = std::move(data);
  return r;
}

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// Byte of a pixel's R, G, B holding bit plane `plane`: 0..7 green, 8..15 red, 16..23 blue.
std::size_t rgb_byte_of_plane(int plane) {
  static constexpr std::size_t kByteOfChannel[] = {1, 0, 2};
  return kByteOfChannel[plane / 8];
}

int image_count(const SequenceConfig& c) {
  return (c.pattern_count + kPatternsPerImage - 1) / kPatternsPerImage;
}

}  // namespace

std::array<std::uint8_t, 3> PatternEntry::encode() const {
  std::uint32_t word = static_cast<std::uint32_t>(trigger) & 0x3;
  word |= (static_cast<std::uint32_t>(pattern_number) & 0x3F) << 2;
  word |= (static_cast<std::uint32_t>(bit_depth) & 0xF) << 8;
  word |= (static_cast<std::uint32_t>(led) & 0x7) << 12;
  if (invert) word |= 1u << 16;
  if (insert_black) word |= 1u << 17;
  if (buffer_swap) word |= 1u << 18;
  if (trigger_out_previous) word |= 1u << 19;
  return {static_cast<std::uint8_t>(word), static_cast<std::uint8_t>(word >> 8),
          static_cast<std::uint8_t>(word >> 16)};
}

PatternEntry PatternEntry::decode(const std::uint8_t* bytes) {
  const std::uint32_t word = bytes[0] | bytes[1] << 8 | static_cast<std::uint32_t>(bytes[2]) << 16;
  PatternEntry e;
  e.trigger = static_cast<TriggerType>(word & 0x3);
  e.pattern_number = static_cast<int>((word >> 2) & 0x3F);
  e.bit_depth = static_cast<int>((word >> 8) & 0xF);
  e.led = static_cast<Led>((word >> 12) & 0x7);
  e.invert = (word & (1u << 16)) != 0;
  e.insert_black = (word & (1u << 17)) != 0;
  e.buffer_swap = (word & (1u << 18)) != 0;
  e.trigger_out_previous = (word & (1u << 19)) != 0;
  return e;
}

std::string plane_name(int pattern_number) {
  static constexpr char kChannel[] = {'G', 'R', 'B'};
  if (pattern_number < 0 || pattern_number >= kPatternsPerImage) {
    return "pattern " + std::to_string(pattern_number);
  }
  return std::string(1, kChannel[pattern_number / 8]) + std::to_string(pattern_number % 8);
}

std::uint8_t trigger_delay_code(double delay_us) {
  const long code = kDelayZeroCode + std::lround(delay_us / kDelayStepUs);
  if (code < 0 || code > 0xFF) {
    throw std::invalid_argument("trigger out delay " + std::to_string(delay_us) +
                                " us is outside " + std::to_string(-kDelayZeroCode * kDelayStepUs) +
                                ".." + std::to_string((0xFF - kDelayZeroCode) * kDelayStepUs) +
                                " us (107.2 ns steps)");
  }
  return static_cast<std::uint8_t>(code);
}

std::string check(const SequenceConfig& c) {
  if (c.pattern_count < 1 || c.pattern_count > kMaxLutEntries) {
    return "pattern_count " + std::to_string(c.pattern_count) + " is not 1.." +
           std::to_string(kMaxLutEntries) + " (pattern LUT entries)";
  }
  if (c.first_flash_image < 0 || c.first_flash_image + image_count(c) > 256 ||
      image_count(c) > kMaxImageEntries) {
    return "flash images " + std::to_string(c.first_flash_image) + ".." +
           std::to_string(c.first_flash_image + image_count(c) - 1) +
           " do not fit the image LUT (1 byte each, at most " + std::to_string(kMaxImageEntries) +
           " entries)";
  }
  if (c.exposure_us <= 0 || c.frame_period_us <= 0) {
    return "exposure_us " + std::to_string(c.exposure_us) + " and frame_period_us " +
           std::to_string(c.frame_period_us) + " must be positive";
  }
  if (c.trigger == TriggerType::kInternal && c.frame_period_us < c.exposure_us) {
    return "frame_period_us " + std::to_string(c.frame_period_us) +
           " is shorter than exposure_us " + std::to_string(c.exposure_us);
  }
  try {
    (void)trigger_delay_code(c.trigger_out1.rising_delay_us);
    (void)trigger_delay_code(c.trigger_out1.falling_delay_us);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

std::vector<PatternEntry> pattern_lut(const SequenceConfig& c) {
  std::vector<PatternEntry> lut;
  lut.reserve(static_cast<std::size_t>(c.pattern_count));
  for (int k = 0; k < c.pattern_count; ++k) {
    const FlashSlot slot = flash_slot(k);
    PatternEntry e;
    e.trigger = c.trigger;
    e.pattern_number = slot.bit_plane;
    e.bit_depth = 1;
    e.led = c.led;
    e.buffer_swap = slot.bit_plane == 0;
    lut.push_back(e);
  }
  return lut;
}

std::vector<std::uint8_t> image_lut(const SequenceConfig& c) {
  std::vector<std::uint8_t> images;
  for (int i = 0; i < image_count(c); ++i) {
    images.push_back(static_cast<std::uint8_t>(c.first_flash_image + i));
  }
  return images;
}

std::vector<std::uint8_t> image_lut_mailbox_bytes(const std::vector<std::uint8_t>& images) {
  if (images.size() == 2) return {images[1], images[0]};
  return images;
}

std::vector<Request> configure_requests(const SequenceConfig& c) {
  if (const std::string problem = check(c); !problem.empty()) {
    throw std::invalid_argument("projector sequence: " + problem);
  }
  const std::vector<PatternEntry> lut = pattern_lut(c);
  const std::vector<std::uint8_t> images = image_lut(c);
  std::vector<Request> out;
  out.push_back(write(Command::kPatternStartStop, {0}));  // stop before changing anything
  out.push_back(write(Command::kDisplayMode, {1}));       // pattern sequence mode
  out.push_back(write(Command::kPatternSource, {3}));     // patterns from flash
  out.push_back(write(Command::kPatternTriggerMode, {1}));
  std::vector<std::uint8_t> timing;
  put_u32(timing, static_cast<std::uint32_t>(c.exposure_us));
  put_u32(timing, static_cast<std::uint32_t>(c.frame_period_us));
  out.push_back(write(Command::kExposureFramePeriod, timing));
  out.push_back(
      write(Command::kTriggerOut1, {static_cast<std::uint8_t>(c.trigger_out1.invert ? 1 : 0),
                                    trigger_delay_code(c.trigger_out1.rising_delay_us),
                                    trigger_delay_code(c.trigger_out1.falling_delay_us)}));
  // Entry counts are sent minus one; trigger out 2 pulses once per cycle.
  const auto n = static_cast<std::uint8_t>(c.pattern_count - 1);
  out.push_back(write(Command::kPatternConfig, {n, static_cast<std::uint8_t>(c.repeat ? 1 : 0), n,
                                                static_cast<std::uint8_t>(images.size() - 1)}));
  std::vector<std::uint8_t> lut_bytes;
  for (const PatternEntry& e : lut) {
    const auto b = e.encode();
    lut_bytes.insert(lut_bytes.end(), b.begin(), b.end());
  }
  out.push_back(write(Command::kMailboxControl, {2}));  // open the pattern LUT
  out.push_back(write(Command::kMailboxAddress, {0}));
  out.push_back(write(Command::kMailboxData, lut_bytes));
  out.push_back(write(Command::kMailboxControl, {0}));
  out.push_back(write(Command::kMailboxControl, {1}));  // open the image LUT
  out.push_back(write(Command::kMailboxAddress, {0}));
  out.push_back(write(Command::kMailboxData, image_lut_mailbox_bytes(images)));
  out.push_back(write(Command::kMailboxControl, {0}));
  out.push_back(write(Command::kValidate, {0}));
  return out;
}

std::vector<FlashImage> pack_flash_images(const std::vector<std::vector<std::uint8_t>>& patterns,
                                          int width, int height) {
  const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const int count = static_cast<int>(patterns.size());
  std::vector<FlashImage> images(
      static_cast<std::size_t>((count + kPatternsPerImage - 1) / kPatternsPerImage));
  for (FlashImage& image : images) {
    image.width = width;
    image.height = height;
    image.rgb.assign(pixels * 3, 0);
  }
  for (int k = 0; k < count; ++k) {
    const std::vector<std::uint8_t>& p = patterns[static_cast<std::size_t>(k)];
    if (p.size() != pixels) {
      throw std::invalid_argument("pattern " + std::to_string(k) + " has " +
                                  std::to_string(p.size()) + " pixels, expected " +
                                  std::to_string(width) + " x " + std::to_string(height));
    }
    const FlashSlot slot = flash_slot(k);
    const std::size_t byte = rgb_byte_of_plane(slot.bit_plane);
    const auto bit = static_cast<std::uint8_t>(1u << (slot.bit_plane % 8));
    std::vector<std::uint8_t>& rgb = images[static_cast<std::size_t>(slot.image)].rgb;
    for (std::size_t i = 0; i < pixels; ++i) {
      if (p[i] >= 128) rgb[3 * i + byte] |= bit;
    }
  }
  return images;
}

bool flash_pixel_lit(const std::vector<FlashImage>& images, int k, int x, int y) {
  const FlashSlot slot = flash_slot(k);
  const FlashImage& image = images.at(static_cast<std::size_t>(slot.image));
  const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                        static_cast<std::size_t>(x);
  const std::uint8_t v = image.rgb.at(3 * i + rgb_byte_of_plane(slot.bit_plane));
  return (v >> (slot.bit_plane % 8) & 1) != 0;
}

std::vector<std::uint8_t> encode_bmp24(const FlashImage& image) {
  const auto w = static_cast<std::uint32_t>(image.width);
  const auto h = static_cast<std::uint32_t>(image.height);
  const std::uint32_t row_bytes = (w * 3 + 3) / 4 * 4;
  const std::uint32_t data_bytes = row_bytes * h;
  constexpr std::uint32_t kHeaders = 14 + 40;
  std::vector<std::uint8_t> out;
  out.reserve(kHeaders + data_bytes);
  const auto u16 = [&out](std::uint32_t v) {
    out.push_back(static_cast<std::uint8_t>(v));
    out.push_back(static_cast<std::uint8_t>(v >> 8));
  };
  const auto u32 = [&out](std::uint32_t v) { put_u32(out, v); };
  out.push_back('B');
  out.push_back('M');
  u32(kHeaders + data_bytes);  // file size
  u32(0);                      // reserved
  u32(kHeaders);               // pixel data offset
  u32(40);                     // BITMAPINFOHEADER
  u32(w);
  u32(h);  // positive: bottom-up rows
  u16(1);  // planes
  u16(24);
  u32(0);  // BI_RGB, uncompressed
  u32(data_bytes);
  u32(2835);  // 72 dpi, as image editors write it
  u32(2835);
  u32(0);
  u32(0);
  for (std::uint32_t row = h; row-- > 0;) {
    const std::uint8_t* src = image.rgb.data() + static_cast<std::size_t>(row) * w * 3;
    for (std::uint32_t x = 0; x < w; ++x) {
      out.push_back(src[3 * x + 2]);
      out.push_back(src[3 * x + 1]);
      out.push_back(src[3 * x + 0]);
    }
    for (std::uint32_t pad = w * 3; pad < row_bytes; ++pad) out.push_back(0);
  }
  return out;
}

}  // namespace avs::projector
