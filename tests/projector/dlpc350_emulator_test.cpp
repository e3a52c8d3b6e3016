// The DLPC350 client and the connection state machine against the byte-exact emulator: the
// paper's sequence configured, validated and started; a sequence the controller rejects, refused
// with its status words; a USB read timeout; the device unplugged mid-run and plugged back.
#include <gtest/gtest.h>

#include "avs/projector/dlpc350_client.hpp"
#include "avs/projector/dlpc350_emulator.hpp"
#include "avs/projector/projector_link.hpp"

namespace avs::projector {
namespace {

using std::chrono::milliseconds;

/// An emulated controller with one handle and a client on it.
struct Bench {
  explicit Bench(EmulatorConfig config = {})
      : device(std::make_shared<Dlpc350Emulator>(config)),
        transport(open(device)),
        client(*transport, milliseconds(100)) {}
  static std::unique_ptr<HidTransport> open(const std::shared_ptr<Dlpc350Emulator>& d) {
    std::string why;
    auto t = emulator_opener(d)(why);
    if (!t) throw std::runtime_error(why);
    return t;
  }
  /// The paper's sequence configured, validated and started.
  void run_paper_sequence() {
    if (!client.configure(SequenceConfig{}, 10).valid()) throw std::runtime_error("invalid");
    client.start();
  }
  std::shared_ptr<Dlpc350Emulator> device;
  std::unique_ptr<HidTransport> transport;
  Dlpc350Client client;
};

std::string all_text(const std::vector<LinkEvent>& events) {
  std::string s;
  for (const LinkEvent& e : events) s += e.text + "\n";
  return s;
}

TEST(Dlpc350Emulator, ClientConfiguresThePaperSequence) {
  Bench bench(EmulatorConfig{.flash_image_count = 1, .busy_reads = 3});
  Dlpc350Client& client = bench.client;
  Dlpc350Emulator& device = *bench.device;

  const DeviceStatus status = client.read_status();
  EXPECT_TRUE(status.ok()) << status.words();
  EXPECT_FALSE(status.running());

  const Validation v = client.configure(SequenceConfig{}, 10);
  EXPECT_TRUE(v.clean()) << join_words(validation_words(v));
  client.start();
  EXPECT_TRUE(device.running());
  EXPECT_TRUE(device.pattern_mode());
  EXPECT_EQ(device.exposure_us(), 1000u);
  EXPECT_EQ(device.frame_period_us(), 1000u);
  EXPECT_EQ(device.pattern_lut(), pattern_lut(SequenceConfig{}));
  EXPECT_EQ(device.image_lut(), std::vector<std::uint8_t>{0});
  EXPECT_EQ(device.trigger_out1(), (std::array<std::uint8_t, 3>{0, 0xBB, 0xBB}));
  EXPECT_TRUE(client.read_status().running());

  // Byte for byte: the first report is a read of STATUS_HW numbered 0; the start (write with
  // reply, length 3, PAT_START_STOP, 2) follows the validation reads, 3 busy and 1 done.
  const std::vector<Report> sent = device.received();
  const auto head = [](const Report& r, int n) {
    return std::vector<std::uint8_t>(r.begin(), r.begin() + n);
  };
  ASSERT_EQ(sent.size(), 3u + 16u + 4u + 1u + 3u);
  EXPECT_EQ(head(sent.front(), 6), (std::vector<std::uint8_t>{0xC0, 0x00, 0x02, 0x00, 0x0A, 0x1A}));
  const Report& start = sent[3 + 16 + 4];
  EXPECT_EQ(head(start, 7), (std::vector<std::uint8_t>{0x40, 23, 0x03, 0x00, 0x24, 0x1A, 0x02}));
}

TEST(Dlpc350Emulator, ChangingARunningSequenceIsNacked) {
  Bench bench;
  bench.run_paper_sequence();
  try {
    bench.client.write(Command::kExposureFramePeriod, {0, 0, 0, 0, 0, 0, 0, 0});
    FAIL() << "no NACK";
  } catch (const Dlpc350Error& e) {
    EXPECT_EQ(e.kind(), Dlpc350Error::Kind::kNack);
    EXPECT_NE(std::string(e.what()).find("PAT_EXPO_PRD"), std::string::npos) << e.what();
  }
}

TEST(Dlpc350Emulator, RejectedSequenceIsRefusedWithTheStatusWords) {
  auto device = std::make_shared<Dlpc350Emulator>();
  LinkConfig config;
  config.sequence.exposure_us = 100;  // below the 1-bit minimum exposure of the controller
  config.sequence.frame_period_us = 100;
  ProjectorLink link(config, emulator_opener(device));
  const std::vector<LinkEvent> events = link.step(SteadyTime{});
  EXPECT_EQ(link.state(), LinkState::kRefused);
  EXPECT_FALSE(device->running());
  EXPECT_EQ(link.validation_words(), "exposure or frame period settings invalid");
  EXPECT_NE(all_text(events).find("refused the sequence (LUT_VALID 0x01): exposure or frame "
                                  "period settings invalid; it is not started"),
            std::string::npos)
      << all_text(events);
  // Refused stays refused: nothing is retried with the same sequence.
  (void)link.step(SteadyTime{} + std::chrono::seconds(10));
  EXPECT_EQ(link.state(), LinkState::kRefused);
  EXPECT_EQ(link.counters().connects, 0u);
}

TEST(Dlpc350Emulator, PatternsMissingFromFlashAreRejected) {
  auto device = std::make_shared<Dlpc350Emulator>(EmulatorConfig{.flash_image_count = 1});
  LinkConfig config;
  config.sequence.first_flash_image = 3;
  ProjectorLink link(config, emulator_opener(device));
  (void)link.step(SteadyTime{});
  EXPECT_EQ(link.state(), LinkState::kRefused);
  EXPECT_EQ(link.validation_words(), "pattern numbers in the LUT invalid");
}

TEST(Dlpc350Emulator, OneReadTimeoutIsCountedAndNotFatal) {
  auto device = std::make_shared<Dlpc350Emulator>();
  LinkConfig config;
  config.status_period = milliseconds(100);
  ProjectorLink link(config, emulator_opener(device));
  SteadyTime t{};
  (void)link.step(t);
  ASSERT_EQ(link.state(), LinkState::kRunning);

  device->drop_replies(1);  // the next status read times out
  t += milliseconds(100);
  const std::vector<LinkEvent> events = link.step(t);
  EXPECT_EQ(link.counters().timeouts, 1u);
  EXPECT_EQ(link.state(), LinkState::kRunning);  // one timeout does not lose the device
  EXPECT_NE(all_text(events).find("read STATUS_HW (sequence "), std::string::npos)
      << all_text(events);
  EXPECT_NE(all_text(events).find("no reply within 200 ms"), std::string::npos);

  t += milliseconds(100);
  (void)link.step(t);
  EXPECT_EQ(link.counters().timeouts, 1u);
  EXPECT_EQ(link.counters().status_reads, 1u);
}

TEST(Dlpc350Emulator, ALateReplyIsNotTakenForTheNextRequest) {
  Bench bench;
  bench.run_paper_sequence();
  bench.device->delay_next_reply();
  // STATUS_HW's reply (0x01) comes late; the next read (STATUS_MAIN, 0x02 when running)
  // must get its own reply, not the stale one.
  EXPECT_THROW((void)bench.client.read(Command::kHardwareStatus, 1), Dlpc350Error);
  EXPECT_EQ(bench.client.read(Command::kMainStatus, 1), std::vector<std::uint8_t>{0x02});

  // Without matching, the stale reply is taken: what match_reply_sequence guards against.
  Dlpc350Client unmatched(*bench.transport, milliseconds(100), /*match_sequence=*/false);
  bench.device->delay_next_reply();
  EXPECT_THROW((void)unmatched.read(Command::kHardwareStatus, 1), Dlpc350Error);
  EXPECT_EQ(unmatched.read(Command::kMainStatus, 1), std::vector<std::uint8_t>{0x01});
}

TEST(Dlpc350Emulator, RepeatedTimeoutsCloseAndReopenTheDevice) {
  auto device = std::make_shared<Dlpc350Emulator>();
  LinkConfig config;
  config.status_period = milliseconds(100);
  config.reconnect_period = milliseconds(500);
  config.timeouts_before_lost = 3;
  ProjectorLink link(config, emulator_opener(device));
  SteadyTime t{};
  (void)link.step(t);
  device->drop_replies(3);
  for (int i = 0; i < 3; ++i) {
    t += milliseconds(100);
    (void)link.step(t);
  }
  EXPECT_EQ(link.state(), LinkState::kDisconnected);
  EXPECT_EQ(link.counters().disconnects, 1u);
  t += milliseconds(500);
  (void)link.step(t);
  EXPECT_EQ(link.state(), LinkState::kRunning);
  EXPECT_EQ(link.counters().connects, 2u);
}

TEST(Dlpc350Emulator, UnpluggedMidRunIsReportedAndReconnectedWhenBack) {
  auto device = std::make_shared<Dlpc350Emulator>();
  LinkConfig config;
  config.status_period = milliseconds(100);
  config.reconnect_period = milliseconds(1000);
  ProjectorLink link(config, emulator_opener(device));
  SteadyTime t{};
  (void)link.step(t);
  ASSERT_EQ(link.state(), LinkState::kRunning);
  ASSERT_TRUE(device->running());

  device->unplug();
  t += milliseconds(100);
  std::vector<LinkEvent> events = link.step(t);
  EXPECT_EQ(link.state(), LinkState::kDisconnected);
  EXPECT_EQ(link.counters().disconnects, 1u);
  EXPECT_NE(all_text(events).find("device gone"), std::string::npos) << all_text(events);
  EXPECT_NE(all_text(events).find("reopening every 1000 ms"), std::string::npos);

  // While it is away: one line for the outage, then quiet retries.
  std::size_t lines = 0;
  for (int i = 0; i < 5; ++i) {
    t += milliseconds(1000);
    lines += link.step(t).size();
  }
  EXPECT_EQ(lines, 1u);
  EXPECT_EQ(link.counters().connect_failures, 5u);
  EXPECT_NE(link.last_error().find("unplugged"), std::string::npos) << link.last_error();

  // Back (power-on state: video mode, empty LUTs): configured from scratch and started.
  device->plug_in();
  EXPECT_FALSE(device->running());
  t += milliseconds(1000);
  events = link.step(t);
  EXPECT_EQ(link.state(), LinkState::kRunning) << all_text(events);
  EXPECT_TRUE(device->running());
  EXPECT_EQ(device->pattern_lut(), pattern_lut(SequenceConfig{}));
  EXPECT_EQ(link.counters().connects, 2u);
  EXPECT_NE(all_text(events).find("sequence started: 18 1-bit patterns"), std::string::npos);
}

TEST(Dlpc350Emulator, AbsentAtStartIsRetriedNotFatal) {
  auto device = std::make_shared<Dlpc350Emulator>();
  device->unplug();
  ProjectorLink link(LinkConfig{}, emulator_opener(device));
  (void)link.step(SteadyTime{});
  EXPECT_EQ(link.state(), LinkState::kDisconnected);
  device->plug_in();
  (void)link.step(SteadyTime{} + std::chrono::milliseconds(999));
  EXPECT_EQ(link.state(), LinkState::kDisconnected);  // not yet due
  (void)link.step(SteadyTime{} + std::chrono::milliseconds(1000));
  EXPECT_EQ(link.state(), LinkState::kRunning);
}

TEST(Dlpc350Emulator, CloseStopsTheSequence) {
  auto device = std::make_shared<Dlpc350Emulator>();
  {
    ProjectorLink link(LinkConfig{}, emulator_opener(device));
    (void)link.step(SteadyTime{});
    ASSERT_TRUE(device->running());
  }
  EXPECT_FALSE(device->running());
}

TEST(Dlpc350Emulator, UnknownCommandsAndBadLengthsAreNacked) {
  Bench bench;
  EXPECT_THROW(bench.client.write(Command::kDisplayMode, {1, 2}), Dlpc350Error);
  // No mailbox open:
  EXPECT_THROW(bench.client.write(Command::kMailboxData, {1, 2, 3}), Dlpc350Error);
  EXPECT_THROW(bench.client.start(), Dlpc350Error);  // nothing validated
  EXPECT_FALSE(bench.device->running());
}

}  // namespace
}  // namespace avs::projector
