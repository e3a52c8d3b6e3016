// Issue 20 section 2, bags: `avs bag play` (bag::play, in this process) goes on past a corrupt
// chunk and never waits for years on a corrupted log_time.
#include <filesystem>
#include <limits>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "avs/bag/player.hpp"
#include "avs/testing/test_domain.hpp"
#include "test_bag.hpp"

namespace avs::bag {
namespace {

namespace fs = std::filesystem;
using mcap::test::golden_messages;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("avs_bag_bad_" + std::to_string(getpid()) + "_" + name);
}

void write_file(const fs::path& path, const std::vector<std::byte>& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
  std::fclose(f);
}

/// Golden messages play() publishes (this build has no geometry_msgs/PointStamped type) whose
/// log time is outside [from, to].
std::size_t played_outside(mcap::Timestamp from, mcap::Timestamp to) {
  std::size_t n = 0;
  for (const auto& m : golden_messages()) {
    n += m.topic != "/point" && (m.log_time < from || m.log_time > to) ? 1 : 0;
  }
  return n;
}

PlayOptions quick(const fs::path& file) {
  PlayOptions o;
  o.file = file;
  o.delay_s = 0;
  o.rate = 10;  // the golden content's 0.5 s in 0.05 s
  o.domain = avs::testing::test_domain();
  return o;
}

TEST(BagPlay, SkipsACorruptChunkAndGoesOn) {
  std::vector<mcap::ChunkIndex> chunks;
  const auto bytes = mcap::test::nine_chunk_bag(chunks, 3);
  ASSERT_EQ(chunks.size(), 9u);
  const mcap::ChunkIndex victim = chunks[3];
  const fs::path file = temp_file("corrupt_chunk.mcap");
  write_file(file, bytes);
  ::testing::internal::CaptureStderr();
  const PlayResult result = play(quick(file));
  const std::string err = ::testing::internal::GetCapturedStderr();
  fs::remove(file);
  EXPECT_EQ(result.published, played_outside(victim.message_start_time, victim.message_end_time))
      << err;
  ASSERT_EQ(result.skipped_chunks.size(), 1u) << err;
  EXPECT_NE(
      err.find("skipped the corrupt chunk at offset " + std::to_string(victim.chunk_start_offset)),
      std::string::npos)
      << err;
}

TEST(BagPlay, ACorruptedLogTimeIsABoundedGapAndSaid) {
  // Issue 20 section 2: a corrupted log_time made play wait 73 years. One message stamped near
  // 0 and one 73 years after the rest: both gaps are cut to --max-gap (0.1 s here), each said.
  auto messages = golden_messages();
  mcap::test::TestMessage early = messages.front();
  early.log_time = 5;
  mcap::test::TestMessage late = messages.front();
  late.log_time = messages.back().log_time + 73ull * 365 * 24 * 3600 * 1'000'000'000ull;
  messages.insert(messages.begin(), early);
  messages.push_back(late);
  const fs::path file = temp_file("far_log_time.mcap");
  ASSERT_TRUE(mcap::test::write_test_bag(file, mcap::test::golden_options(mcap::Compression::zstd),
                                         messages)
                  .ok());
  PlayOptions o = quick(file);
  o.max_gap_s = 0.1;
  ::testing::internal::CaptureStderr();
  const PlayResult result = play(o);  // a hang here is the bug (the CTest timeout ends it)
  const std::string err = ::testing::internal::GetCapturedStderr();
  fs::remove(file);
  EXPECT_EQ(result.published, played_outside(1, 0) + 2) << err;
  EXPECT_EQ(result.gaps_shortened, 2u) << err;
  EXPECT_NE(err.find("(a corrupt log_time?): waiting 0.100 s instead"), std::string::npos) << err;
}

}  // namespace
}  // namespace avs::bag
