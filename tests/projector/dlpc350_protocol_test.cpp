// The DLPC350 HID framing against bytes written out by hand from the programmer's guide's
// layout (flags, sequence, little-endian length, CMD3, CMD2, data), and the status words.
#include <gtest/gtest.h>

#include "avs/projector/dlpc350_protocol.hpp"

namespace avs::projector {
namespace {

Report report_of(std::initializer_list<std::uint8_t> head) {
  Report r{};
  std::copy(head.begin(), head.end(), r.begin());
  return r;
}

TEST(Dlpc350Protocol, WriteWithReplyIsOneReportInTheGuidesLayout) {
  Request r;
  r.command = Command::kPatternStartStop;
  r.access = Access::kWrite;
  r.sequence = 5;
  r.data = {2};  // start
  const std::vector<Report> reports = encode(r);
  ASSERT_EQ(reports.size(), 1u);
  // flags 0x40 (write, reply wanted), seq 5, length 3 (2 command bytes + 1), CMD3 0x24, CMD2 0x1A.
  EXPECT_EQ(reports[0], report_of({0x40, 0x05, 0x03, 0x00, 0x24, 0x1A, 0x02}));
}

TEST(Dlpc350Protocol, ReadRequestCarriesOnlyTheCommand) {
  Request r;
  r.command = Command::kHardwareStatus;
  r.access = Access::kRead;
  r.sequence = 0;
  EXPECT_EQ(encode(r).at(0), report_of({0xC0, 0x00, 0x02, 0x00, 0x0A, 0x1A}));
}

TEST(Dlpc350Protocol, ExposureAndPeriodAreLittleEndianWords) {
  Request r;
  r.command = Command::kExposureFramePeriod;
  r.sequence = 0x11;
  r.data = {0xE8, 0x03, 0x00, 0x00, 0xE8, 0x03, 0x00, 0x00};
  EXPECT_EQ(encode(r).at(0), report_of({0x40, 0x11, 0x0A, 0x00, 0x29, 0x1A, 0xE8, 0x03, 0x00, 0x00,
                                        0xE8, 0x03, 0x00, 0x00}));
}

TEST(Dlpc350Protocol, LongPayloadContinuesInHeaderlessReports) {
  Request r;
  r.command = Command::kMailboxData;
  r.sequence = 9;
  for (int i = 0; i < 144; ++i) r.data.push_back(static_cast<std::uint8_t>(i));
  const std::vector<Report> reports = encode(r);
  // 146 payload bytes: 60 in the first report, 64, then 22.
  ASSERT_EQ(reports.size(), 3u);
  EXPECT_EQ(reports[0][2], 146);
  EXPECT_EQ(reports[0][3], 0);
  EXPECT_EQ(reports[0][4], 0x34);
  EXPECT_EQ(reports[0][5], 0x1A);
  EXPECT_EQ(reports[0][6], 0);    // data[0]
  EXPECT_EQ(reports[0][63], 57);  // data[57]: the last in the first report
  EXPECT_EQ(reports[1][0], 58);   // continuation: no header
  EXPECT_EQ(reports[1][63], 121);
  EXPECT_EQ(reports[2][0], 122);
  EXPECT_EQ(reports[2][21], 143);
  EXPECT_EQ(reports[2][22], 0);  // zero padding
  EXPECT_EQ(request_report_count(reports[0]), 3u);

  const DecodedRequest back = decode_request(reports);
  ASSERT_TRUE(back.request) << back.error;
  EXPECT_EQ(back.request->command, Command::kMailboxData);
  EXPECT_EQ(back.request->sequence, 9);
  EXPECT_EQ(back.request->data, r.data);
}

TEST(Dlpc350Protocol, PayloadOverTheControllersBufferIsRefused) {
  Request r;
  r.command = Command::kMailboxData;
  r.data.assign(600, 0);
  EXPECT_THROW((void)encode(r), std::length_error);
}

TEST(Dlpc350Protocol, RepliesDecodeAckNackAndData) {
  const DecodedReply ack = decode_reply(report_of({0x40, 0x07, 0x00, 0x00}));
  ASSERT_TRUE(ack.reply) << ack.error;
  EXPECT_FALSE(ack.reply->nack);
  EXPECT_EQ(ack.reply->sequence, 7);
  EXPECT_TRUE(ack.reply->data.empty());

  const DecodedReply nack = decode_reply(report_of({0x60, 0x08, 0x00, 0x00}));
  ASSERT_TRUE(nack.reply);
  EXPECT_TRUE(nack.reply->nack);

  const DecodedReply status = decode_reply(report_of({0xC0, 0x00, 0x01, 0x00, 0x81}));
  ASSERT_TRUE(status.reply);
  EXPECT_EQ(status.reply->data, std::vector<std::uint8_t>{0x81});

  EXPECT_EQ(encode_reply({false, 7, {}}), report_of({0x40, 0x07, 0x00, 0x00}));
  EXPECT_EQ(encode_reply({true, 8, {}}), report_of({0x60, 0x08, 0x00, 0x00}));
}

TEST(Dlpc350Protocol, MalformedRepliesSayWhichBytes) {
  const DecodedReply no_reply_bit = decode_reply(report_of({0x00, 0x01, 0x00, 0x00}));
  EXPECT_FALSE(no_reply_bit.reply);
  EXPECT_NE(no_reply_bit.error.find("0x00 (byte 0)"), std::string::npos) << no_reply_bit.error;

  const DecodedReply too_long = decode_reply(report_of({0x40, 0x01, 0x40, 0x00}));
  EXPECT_FALSE(too_long.reply);
  EXPECT_NE(too_long.error.find("length 64"), std::string::npos) << too_long.error;
}

TEST(Dlpc350Protocol, StatusBitsBecomeWords) {
  EXPECT_EQ(join_words(hardware_status_words(0x01)), "internal initialisation: done");
  EXPECT_TRUE(hardware_status_ok(0x01));
  EXPECT_FALSE(hardware_status_ok(0x81));
  EXPECT_EQ(join_words(hardware_status_words(0xC0)),
            "internal initialisation: NOT done (error), sequencer abort (the sequencer stopped "
            "on an error), sequencer error");
  EXPECT_EQ(join_words(system_status_words(0x00)), "internal memory test: FAILED");
  EXPECT_EQ(join_words(main_status_words(0x02)), "sequencer running");
  EXPECT_EQ(join_words(main_status_words(0x01)), "DMD parked, sequencer stopped");
}

TEST(Dlpc350Protocol, ValidationBitsBecomeWords) {
  EXPECT_EQ(join_words(validation_words({0x00})), "valid");
  const Validation bad{0x03};
  EXPECT_FALSE(bad.valid());
  EXPECT_EQ(join_words(validation_words(bad)),
            "exposure or frame period settings invalid, pattern numbers in the LUT invalid");
  const Validation warning{0x10};
  EXPECT_TRUE(warning.valid());
  EXPECT_FALSE(warning.clean());
  EXPECT_TRUE(Validation{0x80}.busy());
}

}  // namespace
}  // namespace avs::projector
