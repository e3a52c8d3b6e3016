// The paper's pattern sequence on a DLPC350 (section 4.1: 2n = 18 1-bit Gray-code patterns per
// cycle at 1000 us each, the camera triggered by each pattern), as the controller takes it: the
// pattern LUT (one 3-byte entry per pattern), the image LUT (which 24-bit flash images), the
// ordered configuration writes, and the 24-bit flash images that `avs patterns` writes
// (24 1-bit patterns packed per image, in the LUT's order). No I/O. docs/devices.md section 7.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "avs/projector/dlpc350_protocol.hpp"

namespace avs::projector {

/// Pattern LUT trigger type (bits 1..0 of an entry).
enum class TriggerType : std::uint8_t {
  kInternal = 0,          ///< the controller's own clock (exposure / frame period)
  kExternalPositive = 1,  ///< TRIG_IN_1 rising edge
  kExternalNegative = 2,  ///< TRIG_IN_1 falling edge
  kContinue = 3,          ///< no trigger: continue from the previous pattern
};

/// LEDs lit for a pattern (bits 14..12 of an entry: bit 0 red, 1 green, 2 blue).
enum class Led : std::uint8_t {
  kNone = 0,
  kRed = 1,
  kGreen = 2,
  kYellow = 3,
  kBlue = 4,
  kMagenta = 5,
  kCyan = 6,
  kWhite = 7,
};

/// One pattern LUT entry (programmer's guide, pattern LUT definition).
struct PatternEntry {
  TriggerType trigger = TriggerType::kInternal;
  int pattern_number = 0;  ///< 1-bit: the bit plane 0..23 of the flash image (plane_name)
  int bit_depth = 1;
  Led led = Led::kWhite;
  bool invert = false;
  bool insert_black = false;  ///< a black fill after the pattern (needs 230 us)
  bool buffer_swap = false;   ///< move to the next image of the image LUT before this pattern
  bool trigger_out_previous = false;  ///< share the previous pattern's TRIG_OUT_1 pulse

  std::array<std::uint8_t, 3> encode() const;
  static PatternEntry decode(const std::uint8_t* bytes);
  bool operator==(const PatternEntry&) const = default;
};

/// Bit plane `pattern_number` of a 24-bit image, as the controller numbers 1-bit patterns:
/// 0..7 green bits 0..7, 8..15 red, 16..23 blue ("G0" .. "B7").
std::string plane_name(int pattern_number);

/// Where the k-th pattern of the sequence lives in flash.
struct FlashSlot {
  int image = 0;      ///< offset from the sequence's first flash image
  int bit_plane = 0;  ///< pattern number 0..23
};
constexpr int kPatternsPerImage = 24;
inline FlashSlot flash_slot(int k) {
  return {k / kPatternsPerImage, k % kPatternsPerImage};
}

/// TRIG_OUT_1 (to the camera's trigger input): polarity and edge delays.
struct TriggerOut {
  bool invert = false;  ///< false: active high
  double rising_delay_us = 0;
  double falling_delay_us = 0;
};

/// The delay code of TRIG_OUT1_CTL: 0xBB is 0 us, each step 107.2 ns (0x00: -20.05 us,
/// 0xFF: +6.86 us). Throws std::invalid_argument outside that range.
std::uint8_t trigger_delay_code(double delay_us);

struct SequenceConfig {
  int pattern_count = 18;      ///< 2n patterns per cycle, in `avs patterns`' order
  int exposure_us = 1000;      ///< per pattern (section 3.1: 1000 fps)
  int frame_period_us = 1000;  ///< equal to the exposure, or longer by >= 230 us
  TriggerType trigger = TriggerType::kInternal;  ///< the projector paces the rig
  Led led = Led::kWhite;
  int first_flash_image = 0;  ///< flash image index of the first 24 patterns
  TriggerOut trigger_out1;    ///< one pulse per pattern: the camera's frame trigger
  bool repeat = true;         ///< run the cycle continuously
};

/// What is wrong with `config` before the controller sees it ("" when nothing): counts that
/// the LUTs cannot hold, a non-positive exposure, an internal trigger with period < exposure.
std::string check(const SequenceConfig& config);

/// One entry per pattern: pattern k is bit plane k % 24 of image k / 24, with a buffer swap
/// where an image starts, its own trigger-out pulse (one camera frame per pattern), 1 bit.
std::vector<PatternEntry> pattern_lut(const SequenceConfig& config);

/// The flash image indices, one per 24 patterns.
std::vector<std::uint8_t> image_lut(const SequenceConfig& config);

/// The writes that configure and validate the sequence, in order: stop, pattern display
/// mode, flash source, trigger mode 1, exposure and period, trigger out 1, pattern config,
/// pattern LUT and image LUT through the mailbox, validate. Sequence numbers are 0 (the
/// client numbers them).
std::vector<Request> configure_requests(const SequenceConfig& config);

/// The MBOX_DATA bytes of an image LUT: TI's host code sends a 2-entry image LUT in reverse
/// order (the firmware reads those two swapped); avs does the same.
std::vector<std::uint8_t> image_lut_mailbox_bytes(const std::vector<std::uint8_t>& images);

// ---- Flash images (`avs patterns --out DIR` writes them) ----

/// A 24-bit image, row-major, 3 bytes per pixel in R, G, B order.
struct FlashImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
};

/// Packs 1-bit patterns (8-bit images of width x height, lit where >= 128) into ceil(n / 24)
/// flash images: pattern k into bit plane flash_slot(k).bit_plane of image
/// flash_slot(k).image. Throws std::invalid_argument if a pattern has the wrong size.
std::vector<FlashImage> pack_flash_images(const std::vector<std::vector<std::uint8_t>>& patterns,
                                          int width, int height);

/// Whether pattern `k` lights pixel (x, y) in `images` (the inverse of pack_flash_images).
bool flash_pixel_lit(const std::vector<FlashImage>& images, int k, int x, int y);

/// A 24-bit uncompressed BMP file (BITMAPINFOHEADER, bottom-up rows, BGR, rows padded to 4
/// bytes): what TI's LightCrafter 4500 GUI takes to build a firmware image with patterns.
std::vector<std::uint8_t> encode_bmp24(const FlashImage& image);

}  // namespace avs::projector
