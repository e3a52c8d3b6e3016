// The paper's sequence (18 1-bit patterns from flash, 1000 us, trigger out 1 per pattern) as
// the DLPC350's LUT bytes and configuration writes, and the flash images `avs patterns` writes.
#include <gtest/gtest.h>

#include "avs/projector/pattern_sequence.hpp"

namespace avs::projector {
namespace {

TEST(PatternSequence, LutEntryBitsAsTheGuideDefinesThem) {
  PatternEntry e;
  e.trigger = TriggerType::kInternal;
  e.pattern_number = 0;
  e.bit_depth = 1;
  e.led = Led::kWhite;
  e.buffer_swap = true;
  // bits 1..0 trigger, 7..2 pattern, 11..8 depth, 14..12 LED, 18 buffer swap: 0x047100.
  EXPECT_EQ(e.encode(), (std::array<std::uint8_t, 3>{0x00, 0x71, 0x04}));
  e.pattern_number = 17;
  e.buffer_swap = false;
  e.trigger = TriggerType::kExternalPositive;
  e.led = Led::kBlue;
  e.invert = true;
  e.insert_black = true;
  e.trigger_out_previous = true;
  // 17 << 2 | 1 = 0x45; 4 << 4 | 1 = 0x41; bits 16, 17, 19 = 0x0B.
  EXPECT_EQ(e.encode(), (std::array<std::uint8_t, 3>{0x45, 0x41, 0x0B}));
  const auto bytes = e.encode();
  EXPECT_EQ(PatternEntry::decode(bytes.data()), e);
}

TEST(PatternSequence, PaperSequenceLut) {
  const SequenceConfig c;  // the defaults are the paper's
  EXPECT_EQ(check(c), "");
  const std::vector<PatternEntry> lut = pattern_lut(c);
  ASSERT_EQ(lut.size(), 18u);
  for (int k = 0; k < 18; ++k) {
    const PatternEntry& e = lut[static_cast<std::size_t>(k)];
    EXPECT_EQ(e.pattern_number, k);
    EXPECT_EQ(e.bit_depth, 1);
    EXPECT_EQ(e.trigger, TriggerType::kInternal);
    EXPECT_EQ(e.buffer_swap, k == 0) << k;  // one flash image holds all 18
    EXPECT_FALSE(e.trigger_out_previous);   // a trigger-out pulse per pattern: one camera frame
    EXPECT_FALSE(e.insert_black);
  }
  EXPECT_EQ(image_lut(c), std::vector<std::uint8_t>{0});
  EXPECT_EQ(plane_name(0), "G0");
  EXPECT_EQ(plane_name(8), "R0");
  EXPECT_EQ(plane_name(9), "R1");
  EXPECT_EQ(plane_name(17), "B1");
  EXPECT_EQ(plane_name(23), "B7");
}

TEST(PatternSequence, PaperSequenceWritesInOrderByteForByte) {
  const std::vector<Request> writes = configure_requests(SequenceConfig{});
  std::vector<std::pair<Command, std::vector<std::uint8_t>>> expected = {
      {Command::kPatternStartStop, {0}},
      {Command::kDisplayMode, {1}},
      {Command::kPatternSource, {3}},
      {Command::kPatternTriggerMode, {1}},
      {Command::kExposureFramePeriod, {0xE8, 0x03, 0, 0, 0xE8, 0x03, 0, 0}},
      {Command::kTriggerOut1, {0x00, 0xBB, 0xBB}},
      {Command::kPatternConfig, {17, 1, 17, 0}},
      {Command::kMailboxControl, {2}},
      {Command::kMailboxAddress, {0}},
      {Command::kMailboxData, {}},
      {Command::kMailboxControl, {0}},
      {Command::kMailboxControl, {1}},
      {Command::kMailboxAddress, {0}},
      {Command::kMailboxData, {0}},
      {Command::kMailboxControl, {0}},
      {Command::kValidate, {0}},
  };
  // The pattern LUT: 0x047100 for pattern 0, then k << 2 | 0x007100.
  auto& lut = expected[9].second;
  lut = {0x00, 0x71, 0x04};
  for (int k = 1; k < 18; ++k) {
    lut.insert(lut.end(), {static_cast<std::uint8_t>(k << 2), 0x71, 0x00});
  }
  ASSERT_EQ(writes.size(), expected.size());
  for (std::size_t i = 0; i < writes.size(); ++i) {
    EXPECT_EQ(writes[i].command, expected[i].first) << i << " " << command_name(writes[i].command);
    EXPECT_EQ(writes[i].access, Access::kWrite);
    EXPECT_EQ(writes[i].data, expected[i].second) << i << " " << command_name(writes[i].command);
  }
}

TEST(PatternSequence, MoreThan24PatternsSpanImagesWithBufferSwaps) {
  SequenceConfig c;
  c.pattern_count = 30;
  c.first_flash_image = 4;
  const std::vector<PatternEntry> lut = pattern_lut(c);
  EXPECT_TRUE(lut[0].buffer_swap);
  EXPECT_FALSE(lut[23].buffer_swap);
  EXPECT_TRUE(lut[24].buffer_swap);
  EXPECT_EQ(lut[24].pattern_number, 0);
  EXPECT_EQ(lut[29].pattern_number, 5);
  EXPECT_EQ(image_lut(c), (std::vector<std::uint8_t>{4, 5}));
  // TI's host code sends two image entries swapped.
  EXPECT_EQ(image_lut_mailbox_bytes({4, 5}), (std::vector<std::uint8_t>{5, 4}));
  EXPECT_EQ(image_lut_mailbox_bytes({4, 5, 6}), (std::vector<std::uint8_t>{4, 5, 6}));
}

TEST(PatternSequence, ChecksBeforeTheControllerSeesIt) {
  SequenceConfig c;
  c.frame_period_us = 900;
  EXPECT_NE(check(c).find("shorter than exposure_us"), std::string::npos) << check(c);
  EXPECT_THROW((void)configure_requests(c), std::invalid_argument);
  c = {};
  c.pattern_count = 0;
  EXPECT_NE(check(c).find("pattern_count 0"), std::string::npos);
  c = {};
  c.trigger_out1.rising_delay_us = 50;
  EXPECT_NE(check(c).find("trigger out delay"), std::string::npos) << check(c);
}

TEST(PatternSequence, TriggerDelayCodes) {
  EXPECT_EQ(trigger_delay_code(0), 0xBB);
  EXPECT_EQ(trigger_delay_code(-20.05), 0x00);
  EXPECT_EQ(trigger_delay_code(1.072), 0xBB + 10);
  EXPECT_THROW((void)trigger_delay_code(-21), std::invalid_argument);
}

TEST(PatternSequence, FlashImagesPackPatternsIntoBitPlanes) {
  const int w = 3, h = 2;
  std::vector<std::vector<std::uint8_t>> patterns(26, std::vector<std::uint8_t>(6, 0));
  patterns[0][0] = 255;   // G0 at (0, 0)
  patterns[9][1] = 255;   // R1 at (1, 0)
  patterns[23][5] = 200;  // B7 at (2, 1)
  patterns[24][2] = 255;  // image 1, G0 at (2, 0)
  patterns[25][3] = 100;  // below 128: dark
  const std::vector<FlashImage> images = pack_flash_images(patterns, w, h);
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].rgb, (std::vector<std::uint8_t>{0x00, 0x01, 0x00,  // (0,0) G bit 0
                                                      0x02, 0x00, 0x00,  // (1,0) R bit 1
                                                      0, 0, 0, 0, 0, 0, 0, 0, 0, 0x00, 0x00,
                                                      0x80}));  // (2,1) B bit 7
  EXPECT_EQ(images[1].rgb[3 * 2 + 1], 0x01);
  for (int k = 0; k < 26; ++k) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        EXPECT_EQ(flash_pixel_lit(images, k, x, y),
                  patterns[static_cast<std::size_t>(k)][static_cast<std::size_t>(y * w + x)] >= 128)
            << k << " " << x << " " << y;
      }
    }
  }
  EXPECT_THROW((void)pack_flash_images({std::vector<std::uint8_t>(5)}, w, h),
               std::invalid_argument);
}

TEST(PatternSequence, Bmp24Layout) {
  FlashImage image{2, 2, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}};
  const std::vector<std::uint8_t> bmp = encode_bmp24(image);
  // 54 header bytes + 2 rows of 6 bytes padded to 8.
  ASSERT_EQ(bmp.size(), 54u + 16u);
  EXPECT_EQ(bmp[0], 'B');
  EXPECT_EQ(bmp[1], 'M');
  EXPECT_EQ(bmp[2], 70);   // file size
  EXPECT_EQ(bmp[10], 54);  // pixel offset
  EXPECT_EQ(bmp[14], 40);  // BITMAPINFOHEADER
  EXPECT_EQ(bmp[18], 2);   // width
  EXPECT_EQ(bmp[22], 2);   // height (bottom-up)
  EXPECT_EQ(bmp[28], 24);  // bits per pixel
  // First stored row is the image's last (y = 1), BGR, then 2 pad bytes.
  EXPECT_EQ(std::vector<std::uint8_t>(bmp.begin() + 54, bmp.end()),
            (std::vector<std::uint8_t>{9, 8, 7, 12, 11, 10, 0, 0, 3, 2, 1, 6, 5, 4, 0, 0}));
}

}  // namespace
}  // namespace avs::projector
