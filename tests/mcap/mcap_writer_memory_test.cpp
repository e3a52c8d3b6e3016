// What an open MCAP writer keeps in memory while a recording grows: the summary's chunk index
// (one Chunk Index record per chunk, written out at close()), and nothing per message. The soak's
// recorder grew by about 50 KiB/min at about 2 chunks a second (docs/reliability.md, "Soak");
// this test measures the writer's share of that without a soak.
#include <malloc.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "avs/mcap/writer.hpp"

namespace avs::mcap {
namespace {

// Bytes the heap has handed out and not got back (glibc's statistics, blocks mapped on their own
// included; background compression is off, so the writer allocates on this thread only).
double heap_in_use_bytes() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd);
}

struct Growth {
  double per_chunk_bytes = 0;
  std::uint64_t messages = 0;
};

// Writes `warm_up` chunks, then `chunks` more of `messages_per_chunk` messages each (four
// channels, as the soak records), and returns how much the heap grew per chunk in between.
Growth grow(const std::filesystem::path& path, int messages_per_chunk, int warm_up, int chunks) {
  Writer writer;
  WriterOptions options;
  options.background_compression = false;  // no second thread's arena in the measurement
  options.profile = "";                    // the ros2 profile's channel metadata is not the point
  if (!writer.open(path, options).ok()) {
    ADD_FAILURE() << "cannot open " << path;
    return {};
  }
  SchemaId schema = 0;
  EXPECT_TRUE(writer.add_schema("std_msgs/msg/String", "ros2msg", "string data", schema).ok());
  std::array<ChannelId, 4> channels{};
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const Status status =
        writer.add_channel("/topic" + std::to_string(c), "cdr", schema, {}, channels[c]);
    if (!status.ok()) {
      ADD_FAILURE() << status.message();
      return {};
    }
  }
  const std::vector<std::byte> payload(100, std::byte{7});
  Timestamp time = 1;
  const auto write_chunks = [&](int count) {
    for (int k = 0; k < count; ++k) {
      for (int m = 0; m < messages_per_chunk; ++m, ++time) {
        ASSERT_TRUE(writer.write(channels[time % channels.size()], time, time, payload).ok());
      }
      ASSERT_TRUE(writer.flush_chunk().ok());
    }
  };
  write_chunks(warm_up);
  const double before = heap_in_use_bytes();
  write_chunks(chunks);
  const double after = heap_in_use_bytes();
  Growth growth{(after - before) / chunks, writer.statistics().message_count};
  EXPECT_TRUE(writer.close().ok());
  return growth;
}

TEST(McapWriterMemory, KeepsAChunkIndexEntryPerChunkAndNothingPerMessage) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "the sanitizer's allocator does not keep glibc's heap statistics (mallinfo2)";
#endif
  const auto directory =
      std::filesystem::temp_directory_path() / ("avs_mcap_memory_" + std::to_string(::getpid()));
  std::filesystem::create_directories(directory);
  // The same number of chunks (so the index buffer ends at the same capacity), 20 times the
  // messages in the second run.
  const Growth few = grow(directory / "few.mcap", 10, 40, 600);
  const Growth many = grow(directory / "many.mcap", 200, 40, 600);
  std::filesystem::remove_all(directory);
  std::printf(
      "heap growth per chunk: %.0f B with 10 messages per chunk, %.0f B with 200 (%llu and "
      "%llu messages)\n",
      few.per_chunk_bytes, many.per_chunk_bytes, static_cast<unsigned long long>(few.messages),
      static_cast<unsigned long long>(many.messages));
  // One serialized Chunk Index record (117 B with four channels and zstd) and the buffer's room
  // to grow (it grows by half); as ChunkIndex structs with a map per entry it was 474-481 B.
  EXPECT_GT(few.per_chunk_bytes, 100.0);
  EXPECT_LT(few.per_chunk_bytes, 256.0);
  // 190 more messages per chunk, 114,000 in all, change it by less than a byte per 3 messages.
  EXPECT_NEAR(many.per_chunk_bytes, few.per_chunk_bytes, 64.0);
}

}  // namespace
}  // namespace avs::mcap
