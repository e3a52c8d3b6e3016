// Truncated, corrupted and malformed files: every failure is an error naming the byte offset,
// never a crash; truncated files stay readable up to their last complete chunk and repair.
#include <gtest/gtest.h>

#include <random>
#include <regex>

#include "avs/mcap/info.hpp"
#include "serialize.hpp"
#include "test_bag.hpp"

namespace avs::mcap::test {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("avs_mcap_bad_" + std::to_string(::getpid()) + "_" + name);
}

void write_bytes(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
  std::fclose(f);
}

std::vector<std::byte> golden(const char* name) {
  return read_bytes(source_dir() / "tests/mcap/data" / name);
}

bool names_an_offset(const Status& s) {
  return std::regex_search(s.message(), std::regex("offset [0-9]+"));
}

/// Reads everything strictly (no truncation tolerated) from memory.
Status read_memory(std::span<const std::byte> bytes, std::vector<ReadMessage>& got,
                   ReadOptions options = {}, ReadReport* report = nullptr) {
  Reader reader;
  if (Status s = reader.open_memory(bytes); !s.ok()) return s;
  return read_all(reader, got, options, report);
}

TEST(McapMalformed, EveryTruncationIsAnErrorNamingTheOffset) {
  const auto bytes = golden("golden_none.mcap");
  ASSERT_GT(bytes.size(), 1000u);
  const auto expected = golden_messages();
  std::size_t previous_count = 0;
  for (std::size_t size = 0; size < bytes.size(); ++size) {
    SCOPED_TRACE("truncated to " + std::to_string(size) + " bytes");
    std::span<const std::byte> cut(bytes.data(), size);
    std::vector<ReadMessage> got;
    ReadOptions summary_only;
    summary_only.allow_fallback_scan = false;
    Status strict = read_memory(cut, got, summary_only);
    ASSERT_FALSE(strict.ok());
    EXPECT_TRUE(names_an_offset(strict)) << strict.to_string();

    // Default: the linear scan either fails naming the offset, or (only the summary was cut)
    // delivers everything and says why the summary was not used.
    ReadReport fallback;
    Status scanned = read_memory(cut, got, {}, &fallback);
    if (scanned.ok()) {
      EXPECT_TRUE(fallback.used_linear_scan);
      EXPECT_TRUE(std::regex_search(fallback.summary_problem, std::regex("offset [0-9]+")))
          << fallback.summary_problem;
      EXPECT_EQ(got.size(), expected.size());
    } else {
      EXPECT_TRUE(names_an_offset(scanned)) << scanned.to_string();
    }

    // Tolerant read: a prefix of the messages, growing with the size, up to complete chunks.
    ReadOptions tolerant;
    tolerant.allow_truncated = true;
    ReadReport report;
    Status s = read_memory(cut, got, tolerant, &report);
    if (size < 8 + 9 + 29) continue;  // magic/header incomplete: nothing to read
    // The summary tail is cut but the data section is intact: everything is there.
    ASSERT_TRUE(s.ok()) << s.to_string();
    ASSERT_LE(got.size(), expected.size());
    EXPECT_GE(got.size(), previous_count);
    previous_count = got.size();
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].log_time, expected[i].log_time);
      ASSERT_TRUE(got[i].data == expected[i].data);
    }
  }
  EXPECT_EQ(previous_count, expected.size());
}

TEST(McapMalformed, AFileKilledRightAfterOpenHasItsHeaderAndIsRepaired) {
  // Issue 20 section 2: a recorder killed in its first half second left a 0-byte file that
  // neither `info` nor `repair` accepted. The magic and the Header record reach the file at
  // open(); what a kill leaves then (a copy of the file while the writer is still open) repairs
  // into a valid empty bag.
  const auto path = temp_path("just_opened.mcap");
  const auto copy = temp_path("just_opened_copy.mcap");
  const auto output = temp_path("just_opened_repaired.mcap");
  Writer writer;
  ASSERT_TRUE(writer.open(path).ok());
  std::filesystem::copy_file(path, copy, std::filesystem::copy_options::overwrite_existing);
  EXPECT_GT(std::filesystem::file_size(copy), 8u) << "the header is not in the file yet";
  RepairReport report;
  const Status repaired = repair_file(copy, output, report);
  EXPECT_TRUE(repaired.ok()) << repaired.to_string();
  EXPECT_EQ(report.messages_kept, 0u);
  Reader reader;
  ASSERT_TRUE(reader.open(output).ok());
  EXPECT_TRUE(reader.read_summary().ok());
  ASSERT_TRUE(writer.close().ok());
  for (const auto& p : {path, copy, output}) std::filesystem::remove(p);
}

TEST(McapMalformed, TruncatedFileIsRepaired) {
  // Arrange: cut in the middle of a late chunk, like a recorder killed mid-write.
  const auto bytes = golden("golden_zstd.mcap");
  Reader reference;
  ASSERT_TRUE(reference.open_memory(bytes).ok());
  ASSERT_TRUE(reference.read_summary().ok());
  const auto& chunks = reference.summary().chunk_indexes;
  ASSERT_GT(chunks.size(), 3u);
  const ChunkIndex& victim = chunks[chunks.size() - 2];
  const std::size_t cut = victim.chunk_start_offset + victim.chunk_length / 2;
  const auto input = temp_path("killed.mcap");
  const auto output = temp_path("repaired.mcap");
  write_bytes(input, std::span(bytes.data(), cut));

  // Act
  RepairReport report;
  Status repaired = repair_file(input, output, report);

  // Verify: summary present, CRCs valid, every message before the cut chunk is there.
  ASSERT_TRUE(repaired.ok()) << repaired.to_string();
  EXPECT_FALSE(report.input_had_summary);
  EXPECT_TRUE(report.input_truncated);
  EXPECT_NE(report.stopped_because.find("offset " + std::to_string(victim.chunk_start_offset)),
            std::string::npos)
      << report.stopped_because;
  Reader reader;
  ASSERT_TRUE(reader.open(output).ok());
  ASSERT_TRUE(reader.read_summary().ok());
  std::vector<ReadMessage> got;
  ReadReport read_report;
  ASSERT_TRUE(read_all(reader, got, {}, &read_report).ok());
  EXPECT_TRUE(read_report.used_summary);
  std::uint64_t kept = 0;
  const auto expected = golden_messages();
  for (const auto& m : expected) kept += m.log_time < victim.message_start_time ? 1 : 0;
  EXPECT_EQ(got.size(), kept);
  EXPECT_EQ(report.messages_kept, kept);
  for (std::size_t i = 0; i < got.size(); ++i) ASSERT_TRUE(got[i].data == expected[i].data);
  ScanResult scanned;
  Status scan = reader.scan(scanned);
  EXPECT_TRUE(scan.ok()) << scan.to_string();
  EXPECT_TRUE(scanned.data_crc_checked);
  // Repair in place works too, and an intact file comes out with the same messages.
  RepairReport again;
  ASSERT_TRUE(repair_file(output, output, again).ok());
  EXPECT_EQ(again.messages_kept, kept);
  EXPECT_TRUE(again.stopped_because.empty()) << again.stopped_because;
  std::filesystem::remove(input);
  std::filesystem::remove(output);
}

TEST(McapMalformed, CorruptChunkIsACrcErrorNamingTheChunkOffset) {
  auto bytes = golden("golden_none.mcap");
  Reader reference;
  ASSERT_TRUE(reference.open_memory(bytes).ok());
  ASSERT_TRUE(reference.read_summary().ok());
  const ChunkIndex chunk = reference.summary().chunk_indexes.at(2);
  // Flip a byte in the middle of the chunk's records (inside a message payload).
  bytes[chunk.chunk_start_offset + chunk.chunk_length - 20] ^= std::byte{0x40};
  std::vector<ReadMessage> got;
  Status s = read_memory(bytes, got);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::crc_mismatch) << s.to_string();
  EXPECT_NE(s.message().find("Chunk record at offset " + std::to_string(chunk.chunk_start_offset)),
            std::string::npos)
      << s.to_string();
}

TEST(McapMalformed, CorruptCompressedChunkIsAnError) {
  for (const char* name : {"golden_lz4.mcap", "golden_zstd.mcap"}) {
    SCOPED_TRACE(name);
    auto bytes = golden(name);
    Reader reference;
    ASSERT_TRUE(reference.open_memory(bytes).ok());
    ASSERT_TRUE(reference.read_summary().ok());
    const ChunkIndex chunk = reference.summary().chunk_indexes.at(1);
    bytes[chunk.chunk_start_offset + chunk.chunk_length - chunk.compressed_size / 2] ^=
        std::byte{0x10};
    std::vector<ReadMessage> got;
    Status s = read_memory(bytes, got);
    ASSERT_FALSE(s.ok());
    EXPECT_TRUE(s.code() == StatusCode::crc_mismatch || s.code() == StatusCode::malformed)
        << s.to_string();
    EXPECT_NE(s.message().find("offset " + std::to_string(chunk.chunk_start_offset)),
              std::string::npos)
        << s.to_string();
  }
}

TEST(McapMalformed, CorruptSummaryIsDetectedAndTheScanStillReads) {
  auto bytes = golden("golden_none.mcap");
  Reader reference;
  ASSERT_TRUE(reference.open_memory(bytes).ok());
  ASSERT_TRUE(reference.read_summary().ok());
  const std::uint64_t summary_start = reference.footer().summary_start;
  bytes[summary_start + 12] ^= std::byte{0x01};
  Reader reader;
  ASSERT_TRUE(reader.open_memory(bytes).ok());
  Status s = reader.read_summary();
  EXPECT_EQ(s.code(), StatusCode::crc_mismatch) << s.to_string();
  EXPECT_NE(s.message().find("offset " + std::to_string(summary_start)), std::string::npos)
      << s.to_string();
  std::vector<ReadMessage> got;
  ReadReport report;
  ASSERT_TRUE(read_all(reader, got, {}, &report).ok());
  EXPECT_TRUE(report.used_linear_scan);
  EXPECT_EQ(got.size(), golden_messages().size());
}

TEST(McapMalformed, CorruptMessageIndexFailsTheDataSectionCrc) {
  auto bytes = golden("golden_none.mcap");
  Reader reference;
  ASSERT_TRUE(reference.open_memory(bytes).ok());
  ASSERT_TRUE(reference.read_summary().ok());
  const ChunkIndex chunk = reference.summary().chunk_indexes.at(1);
  const std::uint64_t index_offset = chunk.message_index_offsets.begin()->second;
  bytes[index_offset + 9 + 2 + 4 + 3] ^= std::byte{0x01};  // a log_time byte: not chunk CRC'd
  Reader reader;
  ASSERT_TRUE(reader.open_memory(bytes).ok());
  ScanResult scanned;
  Status s = reader.scan(scanned);
  EXPECT_EQ(s.code(), StatusCode::crc_mismatch) << s.to_string();
  EXPECT_NE(s.message().find("Data End record at offset"), std::string::npos) << s.to_string();
}

TEST(McapMalformed, HostileFieldsAreRejectedWithOffsets) {
  const auto original = golden("golden_none.mcap");
  Reader reference;
  ASSERT_TRUE(reference.open_memory(original).ok());
  ASSERT_TRUE(reference.read_summary().ok());
  const ChunkIndex chunk = reference.summary().chunk_indexes.at(1);
  std::vector<ReadMessage> got;

  auto bad_magic = original;
  bad_magic[1] = std::byte{'X'};
  Status s = read_memory(bad_magic, got);
  EXPECT_EQ(s.code(), StatusCode::malformed);
  EXPECT_TRUE(names_an_offset(s)) << s.to_string();

  auto huge = original;  // uncompressed_size of a chunk = 2^62
  detail::write_u64_at(huge.data() + chunk.chunk_start_offset + 9 + 16, 1ull << 62);
  s = read_memory(huge, got);
  EXPECT_EQ(s.code(), StatusCode::too_large) << s.to_string();
  EXPECT_TRUE(names_an_offset(s)) << s.to_string();

  auto long_record = original;  // a record length running far past the end of the file
  detail::write_u64_at(long_record.data() + chunk.chunk_start_offset + 1, ~0ull - 5);
  ReadOptions no_summary;
  Reader reader;
  ASSERT_TRUE(reader.open_memory(long_record).ok());
  ScanResult scanned;
  s = reader.scan(scanned);
  EXPECT_EQ(s.code(), StatusCode::truncated) << s.to_string();
  EXPECT_NE(s.message().find("offset " + std::to_string(chunk.chunk_start_offset)),
            std::string::npos)
      << s.to_string();

  auto zero_opcode = original;
  zero_opcode[chunk.chunk_start_offset] = std::byte{0};
  Reader zero_reader;
  ASSERT_TRUE(zero_reader.open_memory(zero_opcode).ok());
  s = zero_reader.scan(scanned);
  EXPECT_EQ(s.code(), StatusCode::malformed) << s.to_string();
  EXPECT_TRUE(names_an_offset(s)) << s.to_string();
}

TEST(McapMalformed, RepairInPlaceKeepsEveryIntactChunkAndNeverWritesOverItsInputWithLess) {
  // Issue 20 section 2: `avs bag repair` in place turned a bag with a valid summary, 8 of its 9
  // chunks intact and one flipped bit into 168 bytes without a message, exit 0.
  std::vector<ChunkIndex> chunks;
  const auto bytes = nine_chunk_bag(chunks, 4);
  ASSERT_EQ(chunks.size(), 9u);
  const ChunkIndex victim = chunks[4];
  const auto input = temp_path("flipped.mcap");
  write_bytes(input, bytes);

  RepairReport report;
  const Status in_place = repair_file(input, input, report);

  // The input is untouched; the result beside it holds every message of the 8 intact chunks.
  EXPECT_EQ(in_place.code(), StatusCode::incomplete) << in_place.to_string();
  EXPECT_NE(in_place.message().find("did not replace"), std::string::npos) << in_place.to_string();
  EXPECT_TRUE(read_bytes(input) == bytes) << "repair wrote over its input";
  ASSERT_EQ(report.skipped_chunks.size(), 1u);
  EXPECT_EQ(report.skipped_chunks[0].offset, victim.chunk_start_offset);
  EXPECT_EQ(report.chunks_kept, 8u);
  EXPECT_TRUE(report.input_had_summary);
  EXPECT_EQ(report.input_summary_messages, golden_messages().size());
  const std::size_t intact = messages_outside(victim);
  EXPECT_EQ(report.messages_kept, intact);
  EXPECT_EQ(report.written_to.string(), input.string() + ".repaired.mcap");
  Reader repaired;
  ASSERT_TRUE(repaired.open(report.written_to).ok());
  ASSERT_TRUE(repaired.read_summary().ok());
  std::vector<ReadMessage> got;
  ASSERT_TRUE(read_all(repaired, got).ok());
  EXPECT_EQ(got.size(), intact);

  // To another file the same result is the asked-for outcome.
  const auto output = temp_path("flipped_out.mcap");
  RepairReport elsewhere;
  const Status to_output = repair_file(input, output, elsewhere);
  EXPECT_TRUE(to_output.ok()) << to_output.to_string();
  EXPECT_EQ(elsewhere.messages_kept, intact);
  EXPECT_EQ(elsewhere.skipped_chunks.size(), 1u);
  for (const auto& p : {input, output, report.written_to}) std::filesystem::remove(p);
}

/// Reads `bytes` as `bag play` does (corrupt chunks skipped, truncation tolerated), through
/// its summary or, `with_summary` false, by a linear scan of it cut after its last chunk.
Status read_skipping(std::vector<std::byte> bytes, bool with_summary,
                     const std::vector<ChunkIndex>& chunks, std::vector<ReadMessage>& got,
                     ReadReport& report) {
  if (!with_summary) bytes.resize(chunks.back().chunk_start_offset + chunks.back().chunk_length);
  ReaderOptions skipping;
  skipping.skip_corrupt_chunks = true;
  Reader reader;
  if (Status s = reader.open_memory(bytes, skipping); !s.ok()) return s;
  ReadOptions options;
  options.allow_truncated = true;
  return read_all(reader, got, options, &report);
}

// Issue 20 section 2: a chunk's length field is one u64 among its bytes. A flipped bit there
// ended repair's scan at that chunk (every chunk after it lost) or, with a length covering the
// next chunk, hid that chunk inside it. The chunk's own fields frame it as well.
TEST(McapMalformed, RepairKeepsEveryChunkWhenAChunksLengthFieldIsCorrupt) {
  std::vector<ChunkIndex> chunks;
  const auto bytes = nine_chunk_bag(chunks, 9);  // nothing flipped
  ASSERT_EQ(chunks.size(), 9u);
  const ChunkIndex& victim = chunks[4];
  const std::uint64_t declared = victim.chunk_length - kRecordPrefixSize;
  const struct {
    const char* name;
    std::uint64_t length;
  } cases[] = {
      {"past the end of the file", std::uint64_t{1} << 40},
      {"shorter than the chunk", declared - 100},
      {"covering the next chunk",
       chunks[6].chunk_start_offset - victim.chunk_start_offset - kRecordPrefixSize},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    auto corrupt = bytes;
    detail::write_u64_at(corrupt.data() + victim.chunk_start_offset + 1, c.length);
    // A strict reader's linear scan refuses it (or, for the covering length, misses a chunk).
    {
      auto no_summary = corrupt;
      no_summary.resize(chunks.back().chunk_start_offset + chunks.back().chunk_length);
      std::vector<ReadMessage> strict;
      ReadOptions options;
      options.allow_truncated = true;
      const Status s = read_memory(no_summary, strict, options);
      EXPECT_TRUE(!s.ok() || strict.size() < golden_messages().size());
    }
    const auto input = temp_path("length_field.mcap");
    const auto output = temp_path("length_field_out.mcap");
    write_bytes(input, corrupt);
    RepairReport report;
    const Status repaired = repair_file(input, output, report);
    ASSERT_TRUE(repaired.ok()) << repaired.to_string();
    EXPECT_TRUE(report.skipped_chunks.empty())
        << report.skipped_chunks.front().offset << ": " << report.skipped_chunks.front().problem;
    EXPECT_EQ(report.chunk_lengths_corrected, 1u);
    EXPECT_EQ(report.chunks_kept, 9u);
    EXPECT_EQ(report.messages_kept, golden_messages().size());
    Reader reader;
    ASSERT_TRUE(reader.open(output).ok());
    ASSERT_TRUE(reader.read_summary().ok());
    std::vector<ReadMessage> got;
    ASSERT_TRUE(read_all(reader, got).ok());
    EXPECT_EQ(got.size(), golden_messages().size());

    // A skipping reader (bag play) reads it whole, through the summary and by a linear scan.
    for (const bool with_summary : {true, false}) {
      SCOPED_TRACE(with_summary ? "through the summary" : "by a linear scan");
      std::vector<ReadMessage> all;
      ReadReport read_report;
      const Status s = read_skipping(corrupt, with_summary, chunks, all, read_report);
      ASSERT_TRUE(s.ok()) << s.to_string();
      EXPECT_TRUE(read_report.skipped_chunks.empty());
      EXPECT_EQ(all.size(), golden_messages().size());
    }
    // In place, a complete and verified result replaces the input.
    RepairReport in_place;
    ASSERT_TRUE(repair_file(input, input, in_place).ok());
    EXPECT_EQ(in_place.written_to, input);
    for (const auto& p : {input, output}) std::filesystem::remove(p);
  }
}

TEST(McapMalformed, RepairResumesAtTheNextIntactChunkWhenFramingIsLost) {
  std::vector<ChunkIndex> chunks;
  const auto bytes = nine_chunk_bag(chunks, 9);
  ASSERT_EQ(chunks.size(), 9u);
  const ChunkIndex& victim = chunks[4];
  {
    SCOPED_TRACE("a chunk whose length field and compression name length are both corrupt");
    auto corrupt = bytes;
    detail::write_u64_at(corrupt.data() + victim.chunk_start_offset + 1, std::uint64_t{1} << 40);
    detail::write_u32_at(corrupt.data() + victim.chunk_start_offset + kRecordPrefixSize + 28,
                         0xFFFFFFF0u);
    const auto input = temp_path("framing.mcap");
    const auto output = temp_path("framing_out.mcap");
    write_bytes(input, corrupt);
    RepairReport report;
    ASSERT_TRUE(repair_file(input, output, report).ok());
    ASSERT_EQ(report.skipped_chunks.size(), 1u);
    EXPECT_EQ(report.skipped_chunks[0].offset, victim.chunk_start_offset);
    EXPECT_NE(report.skipped_chunks[0].problem.find("next intact record, at offset " +
                                                    std::to_string(chunks[5].chunk_start_offset)),
              std::string::npos)
        << report.skipped_chunks[0].problem;
    EXPECT_EQ(report.chunks_kept, 8u);
    EXPECT_EQ(report.messages_kept, messages_outside(victim));
    EXPECT_TRUE(report.stopped_because.empty()) << report.stopped_because;
    for (const auto& p : {input, output}) std::filesystem::remove(p);
  }
  {
    SCOPED_TRACE("a Message Index record whose length field is corrupt");
    auto corrupt = bytes;
    const std::uint64_t index_at = victim.chunk_start_offset + victim.chunk_length;
    ASSERT_EQ(corrupt[index_at], std::byte{static_cast<unsigned char>(Opcode::message_index)});
    detail::write_u64_at(corrupt.data() + index_at + 1, std::uint64_t{1} << 40);
    const auto input = temp_path("index_length.mcap");
    const auto output = temp_path("index_length_out.mcap");
    write_bytes(input, corrupt);
    RepairReport report;
    ASSERT_TRUE(repair_file(input, output, report).ok());
    ASSERT_EQ(report.skipped_chunks.size(), 1u);
    EXPECT_EQ(report.skipped_chunks[0].offset, index_at);
    EXPECT_EQ(report.chunks_kept, 9u);  // the indexes are rebuilt: no message is lost
    EXPECT_EQ(report.messages_kept, golden_messages().size());
    for (const auto& p : {input, output}) std::filesystem::remove(p);
  }
}

TEST(McapMalformed, ASkippingReaderGoesOnPastACorruptChunk) {
  std::vector<ChunkIndex> chunks;
  const auto bytes = nine_chunk_bag(chunks, 2);
  ASSERT_EQ(chunks.size(), 9u);
  const ChunkIndex victim = chunks[2];
  for (const bool with_summary : {true, false}) {
    SCOPED_TRACE(with_summary ? "through the summary" : "by a linear scan");
    std::vector<ReadMessage> got;
    ReadReport report;
    const Status s = read_skipping(bytes, with_summary, chunks, got, report);
    ASSERT_TRUE(s.ok()) << s.to_string();
    EXPECT_EQ(report.used_summary, with_summary);
    ASSERT_EQ(report.skipped_chunks.size(), 1u);
    EXPECT_EQ(report.skipped_chunks[0].offset, victim.chunk_start_offset);
    EXPECT_NE(report.skipped_chunks[0].problem.find("offset"), std::string::npos);
    EXPECT_EQ(got.size(), messages_outside(victim));
  }
  // A strict reader still fails on it.
  std::vector<ReadMessage> got;
  EXPECT_FALSE(read_memory(bytes, got).ok());
}

TEST(McapMalformed, AZstdBombHitsTheDecompressedSizeLimit) {
  // Issue 20 section 2: 8 chunks claiming 128 MiB each (101 KB of zstd) took 2.4 GB. One chunk
  // of 80 MiB of zeros, a few KB compressed: refused by its claimed size before any allocation,
  // and, with a claim of 1 MiB, by the real size when decompressing.
  const auto path = temp_path("bomb.mcap");
  {
    WriterOptions options;
    options.compression = Compression::zstd;
    options.chunk_size_bytes = 96u << 20;
    Writer writer;
    ASSERT_TRUE(writer.open(path, options).ok());
    SchemaId schema = 0;
    ChannelId channel = 0;
    ASSERT_TRUE(writer.add_schema("std_msgs/msg/String", "ros2msg", kStringSchema, schema).ok());
    ASSERT_TRUE(
        writer.add_channel("/bomb", "cdr", schema, {{"offered_qos_profiles", kQos}}, channel).ok());
    const std::vector<std::byte> zeros(1u << 20);
    for (std::uint32_t i = 0; i < 80; ++i) {
      ASSERT_TRUE(writer.write(channel, 1000 + i, 1000 + i, zeros, i).ok());
    }
    ASSERT_TRUE(writer.close().ok());
  }
  auto bytes = read_bytes(path);
  std::filesystem::remove(path);
  EXPECT_LT(bytes.size(), 1u << 20) << "not a bomb";
  Reader reader;
  ASSERT_TRUE(reader.open_memory(bytes).ok());
  ASSERT_TRUE(reader.read_summary().ok());
  ASSERT_EQ(reader.summary().chunk_indexes.size(), 1u);
  const ChunkIndex chunk = reader.summary().chunk_indexes[0];
  std::vector<ReadMessage> got;
  Status s = read_all(reader, got);
  EXPECT_EQ(s.code(), StatusCode::too_large) << s.to_string();
  EXPECT_NE(s.message().find("above the reader limit " +
                             std::to_string(ReaderOptions{}.max_chunk_uncompressed_bytes)),
            std::string::npos)
      << s.to_string();
  EXPECT_TRUE(got.empty());

  auto understated = bytes;  // the chunk claims 1 MiB: decompression stops there
  detail::write_u64_at(understated.data() + chunk.chunk_start_offset + 9 + 16, 1u << 20);
  s = read_memory(understated, got);
  EXPECT_EQ(s.code(), StatusCode::malformed) << s.to_string();
  EXPECT_NE(s.message().find("offset " + std::to_string(chunk.chunk_start_offset)),
            std::string::npos)
      << s.to_string();
}

/// Seeded random mutations of the golden files: each read must end in an error or success,
/// never a crash (the libFuzzer target, run under AddressSanitizer, digs deeper).
TEST(McapFuzz, TwentyThousandSeededMutationsNeverCrash) {
  const std::vector<std::vector<std::byte>> seeds = {
      golden("golden_none.mcap"), golden("golden_lz4.mcap"), golden("golden_zstd.mcap")};
  std::mt19937_64 rng(20240607);
  ReaderOptions limits;
  limits.max_chunk_uncompressed_bytes = 16u << 20;
  std::size_t errors = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::byte> bytes = seeds[static_cast<std::size_t>(i) % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % bytes.size();
      switch (rng() % 4) {
        case 0:
          bytes[at] ^= static_cast<std::byte>(1u << (rng() % 8));
          break;
        case 1:
          bytes[at] = static_cast<std::byte>(rng());
          break;
        case 2:  // a random u64 (often a length field)
          if (at + 8 <= bytes.size()) {
            detail::write_u64_at(bytes.data() + at, rng() % 2 ? rng() : rng() % 4096);
          }
          break;
        case 3:
          bytes.resize(at + 1);
          break;
      }
    }
    Reader reader;
    if (!reader.open_memory(bytes, limits).ok()) {
      ++errors;
      continue;
    }
    ReadOptions options;
    options.allow_truncated = (i % 2) == 0;
    std::uint64_t sum = 0;
    Status s = reader.read_messages(
        [&](const MessageView& view) {
          for (std::byte b : view.data) sum += static_cast<std::uint8_t>(b);
          return true;
        },
        options);
    if (!s.ok()) ++errors;
    ScanResult scanned;
    (void)reader.scan(scanned, true);
  }
  // Most mutations must be caught (CRCs cover everything but the message index contents).
  EXPECT_GT(errors, 10000u);
}

}  // namespace
}  // namespace avs::mcap::test
