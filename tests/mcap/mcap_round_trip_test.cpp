// Writer -> reader round trips, golden files, log-time order, filters and `bag info`.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "avs/mcap/info.hpp"
#include "checksum.hpp"
#include "test_bag.hpp"

namespace avs::mcap::test {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("avs_mcap_" + std::to_string(::getpid()) + "_" + name);
}

void expect_same(const std::vector<TestMessage>& expected, const std::vector<ReadMessage>& got) {
  ASSERT_EQ(expected.size(), got.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    SCOPED_TRACE("message " + std::to_string(i));
    EXPECT_EQ(expected[i].topic, got[i].topic);
    EXPECT_EQ(expected[i].log_time, got[i].log_time);
    EXPECT_EQ(expected[i].publish_time, got[i].publish_time);
    EXPECT_EQ(expected[i].sequence, got[i].sequence);
    EXPECT_TRUE(expected[i].data == got[i].data);
  }
}

const char* golden_name(Compression c) {
  switch (c) {
    case Compression::none:
      return "golden_none.mcap";
    case Compression::lz4:
      return "golden_lz4.mcap";
    case Compression::zstd:
      return "golden_zstd.mcap";
  }
  return "";
}

TEST(McapCrc, MatchesTheCrc32CheckValue) {
  // CRC-32/ISO-HDLC check value for the ASCII digits "123456789".
  const char digits[] = "123456789";
  EXPECT_EQ(detail::crc32_update(0, std::as_bytes(std::span(digits, 9))), 0xCBF43926u);
  // Continuing a CRC over a split input gives the same value.
  std::uint32_t crc = detail::crc32_update(0, std::as_bytes(std::span(digits, 4)));
  EXPECT_EQ(detail::crc32_update(crc, std::as_bytes(std::span(digits + 4, 5))), 0xCBF43926u);
}

class McapCompression : public ::testing::TestWithParam<std::tuple<Compression, bool>> {};

TEST_P(McapCompression, RoundTripIsExact) {
  const auto [compression, background] = GetParam();
  // Arrange: random payload sizes (0 B .. 300 KiB) on three channels, several chunks.
  std::mt19937 rng(42);
  std::vector<TestMessage> messages;
  const char* topics[] = {"/chatter", "/point", "/camera/image"};
  Timestamp t = 1'000'000'000;
  for (int i = 0; i < 300; ++i) {
    TestMessage m;
    m.topic = topics[rng() % 3];
    t += rng() % 1000;
    m.log_time = t;
    m.publish_time = t - rng() % 100;
    m.sequence = static_cast<std::uint32_t>(i);
    std::size_t size = (i % 50 == 0) ? 300 * 1024 : rng() % 5000;
    if (i % 37 == 0) size = 0;
    m.data.resize(size);
    for (auto& b : m.data) b = static_cast<std::byte>(rng() % 7);  // compressible
    messages.push_back(std::move(m));
  }
  WriterOptions options;
  options.compression = compression;
  options.background_compression = background;
  options.chunk_size_bytes = 64 * 1024;
  const auto path = temp_path("round_trip.mcap");

  // Act
  Status written = write_test_bag(path, options, messages);
  ASSERT_TRUE(written.ok()) << written.to_string();
  Reader reader;
  ASSERT_TRUE(reader.open(path).ok());
  std::vector<ReadMessage> got;
  ReadReport report;
  Status read = read_all(reader, got, {}, &report);

  // Verify
  ASSERT_TRUE(read.ok()) << read.to_string();
  EXPECT_TRUE(report.used_summary);
  expect_same(messages, got);
  EXPECT_EQ(reader.header().profile, "ros2");
  ASSERT_TRUE(reader.summary().statistics.has_value());
  EXPECT_EQ(reader.summary().statistics->message_count, messages.size());
  EXPECT_GT(reader.summary().chunk_indexes.size(), 5u);
  for (const ChunkIndex& index : reader.summary().chunk_indexes) {
    EXPECT_EQ(index.compression, std::string(compression_field(compression)));
    // The first chunk holds only Schema and Channel records (the Metadata record closed it).
    if (index.message_end_time != 0) {
      EXPECT_FALSE(index.message_index_offsets.empty());
    }
  }
  // A full linear scan checks the data-section CRC and every chunk CRC.
  ScanResult scanned;
  Status scan = reader.scan(scanned);
  ASSERT_TRUE(scan.ok()) << scan.to_string();
  EXPECT_TRUE(scanned.data_crc_checked);
  EXPECT_EQ(scanned.summary.statistics->message_count, messages.size());
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, McapCompression,
                         ::testing::Combine(::testing::Values(Compression::none, Compression::lz4,
                                                              Compression::zstd),
                                            ::testing::Bool()));

TEST(McapReader, MergesOverlappingChunksInLogTimeOrder) {
  // Arrange: log times go back and forth, so chunks overlap in time.
  std::vector<TestMessage> messages;
  for (int i = 0; i < 200; ++i) {
    TestMessage m;
    m.topic = i % 2 ? "/chatter" : "/point";
    m.log_time = 1000 + static_cast<Timestamp>((i * 7919) % 200) * 10;
    m.publish_time = m.log_time;
    m.sequence = static_cast<std::uint32_t>(i);
    m.data = encode_string("m" + std::to_string(i));
    messages.push_back(m);
  }
  WriterOptions options;
  options.chunk_size_bytes = 512;
  const auto path = temp_path("order.mcap");
  ASSERT_TRUE(write_test_bag(path, options, messages).ok());
  // Act
  Reader reader;
  ASSERT_TRUE(reader.open(path).ok());
  std::vector<ReadMessage> got;
  ASSERT_TRUE(read_all(reader, got).ok());
  // Verify: sorted by log time, ties in write order.
  std::vector<TestMessage> expected = messages;
  std::stable_sort(
      expected.begin(), expected.end(),
      [](const TestMessage& a, const TestMessage& b) { return a.log_time < b.log_time; });
  expect_same(expected, got);
  std::filesystem::remove(path);
}

TEST(McapReader, FiltersByTopicAndTime) {
  const auto messages = golden_messages();
  const auto path = temp_path("filter.mcap");
  ASSERT_TRUE(write_test_bag(path, golden_options(Compression::zstd), messages).ok());
  Reader reader;
  ASSERT_TRUE(reader.open(path).ok());
  ReadOptions options;
  options.topics = {"/point"};
  options.start_time = messages[10].log_time;
  options.end_time = messages[60].log_time;
  std::vector<ReadMessage> got;
  ASSERT_TRUE(read_all(reader, got, options).ok());
  std::vector<TestMessage> expected;
  for (const auto& m : messages) {
    if (m.topic == "/point" && m.log_time >= options.start_time && m.log_time <= options.end_time) {
      expected.push_back(m);
    }
  }
  ASSERT_FALSE(expected.empty());
  expect_same(expected, got);
  std::filesystem::remove(path);
}

class McapGolden : public ::testing::TestWithParam<Compression> {};

TEST_P(McapGolden, GoldenFileReadsBackExactly) {
  const auto golden = source_dir() / "tests/mcap/data" / golden_name(GetParam());
  if (std::getenv("AVS_MCAP_REGENERATE_GOLDEN") != nullptr) {
    ASSERT_TRUE(write_test_bag(golden, golden_options(GetParam()), golden_messages()).ok());
  }
  ASSERT_TRUE(std::filesystem::exists(golden)) << golden;
  Reader reader;
  Status opened = reader.open(golden);
  ASSERT_TRUE(opened.ok()) << opened.to_string();
  std::vector<ReadMessage> got;
  Status read = read_all(reader, got);
  ASSERT_TRUE(read.ok()) << read.to_string();
  expect_same(golden_messages(), got);
  EXPECT_EQ(got[0].schema_name, "std_msgs/msg/String");
  EXPECT_EQ(reader.summary().metadata_indexes.size(), 1u);
  EXPECT_EQ(reader.summary().channels.at(0).metadata.at("offered_qos_profiles"), kQos);
  EXPECT_EQ(reader.summary().schemas.at(2).data, kPointStampedSchema);
}

TEST(McapGoldenBytes, UncompressedWriterOutputIsByteIdenticalToGolden) {
  // Compressed goldens may legitimately differ with another zstd/lz4 version; "none" may not.
  const auto golden = source_dir() / "tests/mcap/data" / golden_name(Compression::none);
  const auto path = temp_path("golden_again.mcap");
  ASSERT_TRUE(write_test_bag(path, golden_options(Compression::none), golden_messages()).ok());
  EXPECT_TRUE(read_bytes(path) == read_bytes(golden));
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, McapGolden,
                         ::testing::Values(Compression::none, Compression::lz4, Compression::zstd));

TEST(McapInfo, ReportsDurationCountsAndRates) {
  const auto golden = source_dir() / "tests/mcap/data" / golden_name(Compression::zstd);
  BagInfo info;
  Status s = read_bag_info(golden, info);
  ASSERT_TRUE(s.ok()) << s.to_string();
  EXPECT_TRUE(info.from_summary);
  EXPECT_EQ(info.message_count, 50u + 25u + 10u);
  ASSERT_EQ(info.topics.size(), 3u);
  EXPECT_EQ(info.topics[0].topic, "/camera/image");
  EXPECT_EQ(info.topics[0].type, "sensor_msgs/msg/Image");
  EXPECT_EQ(info.topics[0].message_count, 10u);
  EXPECT_EQ(info.topics[1].topic, "/chatter");
  EXPECT_EQ(info.topics[1].message_count, 50u);
  // First log time: tick 0 (/chatter); last: tick 49 (/chatter), 490 ms later.
  EXPECT_NEAR(info.duration_s, 0.490, 1e-12);
  EXPECT_NEAR(info.topics[1].rate_hz, 50 / 0.490, 1e-9);
  EXPECT_EQ(info.chunks_by_compression.at("zstd"), info.chunk_count);
  const std::string text = format_bag_info(info);
  EXPECT_NE(text.find("sensor_msgs/msg/Image"), std::string::npos) << text;
  EXPECT_NE(text.find("Duration:"), std::string::npos) << text;
}

TEST(McapWriter, RejectsWhatTheRos2ProfileForbids) {
  Writer writer;
  const auto path = temp_path("reject.mcap");
  ASSERT_TRUE(writer.open(path).ok());
  SchemaId schema = 0;
  EXPECT_FALSE(writer.add_schema("x/msg/Y", "jsonschema", "{}", schema).ok());
  ASSERT_TRUE(writer.add_schema("std_msgs/msg/String", "ros2msg", kStringSchema, schema).ok());
  ChannelId channel = 0;
  EXPECT_FALSE(
      writer.add_channel("/a", "json", schema, {{"offered_qos_profiles", ""}}, channel).ok());
  EXPECT_FALSE(writer.add_channel("/a", "cdr", schema, {}, channel).ok());
  EXPECT_FALSE(writer.add_channel("/a", "cdr", 99, {{"offered_qos_profiles", ""}}, channel).ok());
  EXPECT_FALSE(writer.write(7, 1, 1, {}).ok());
  EXPECT_TRUE(writer.close().ok());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace avs::mcap::test
