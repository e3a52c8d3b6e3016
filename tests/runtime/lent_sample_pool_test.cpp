// LentSamplePool (the camera's lent frames): a sample's bytes are the caller's, not copied and
// never freed by the sample; its lease stays while anyone holds the sample and goes at the next
// lend or release_unused() after that; a sample may outlive its pool. Allocations are counted in
// tests/realtime (camera_allocations_test.cpp); this runs in the sanitizer builds too.
#include "avs/runtime/lent_sample_pool.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>

#include "avs/runtime/sample.hpp"
#include "avs_msgs.h"

namespace avs::runtime {
namespace {

using PatternFrame = msgs::avs_msgs::PatternFrame;

dds_sequence_uint8& image_bytes(PatternFrame& p) {
  return p.image.data;
}

TEST(LentSamplePool, TheBytesAreLentAndTheLeaseGoesAfterTheLastHolder) {
  std::array<std::uint8_t, 16> buffer{};
  const auto lease = std::make_shared<int>(0);  // out while its use count is above 1
  LentSamplePool<PatternFrame> pool(&image_bytes);
  std::shared_ptr<const PatternFrame> held = pool.lend(buffer.data(), buffer.size(), lease);
  EXPECT_EQ(held->image.data._buffer, buffer.data());
  EXPECT_EQ(held->image.data._length, buffer.size());
  EXPECT_FALSE(held->image.data._release);
  EXPECT_EQ(lease.use_count(), 2);
  pool.release_unused();
  EXPECT_EQ(lease.use_count(), 2) << "held: the lease stays";
  held.reset();
  EXPECT_EQ(lease.use_count(), 2) << "the kept sample keeps it until the next sweep";
  pool.release_unused();
  EXPECT_EQ(lease.use_count(), 1);
}

TEST(LentSamplePool, AKeptSampleComesBackWithItsStringsOnlyOnceNobodyHoldsIt) {
  std::array<std::uint8_t, 16> a{}, b{};
  const auto lease = std::make_shared<int>(0);
  LentSamplePool<PatternFrame> pool(&image_bytes, 1);
  auto first = pool.lend(a.data(), a.size(), lease);
  set_string(first->header.frame_id, "camera_optical");
  const PatternFrame* kept = first.get();
  const char* storage = first->header.frame_id;
  std::shared_ptr<const PatternFrame> held = std::move(first);
  auto second = pool.lend(b.data(), b.size(), lease);
  EXPECT_NE(second.get(), kept) << "held: not handed out again";
  second.reset();  // beyond max_kept: made for one use, its lease goes with it
  EXPECT_EQ(lease.use_count(), 2);
  held.reset();
  auto third = pool.lend(b.data(), b.size(), lease);
  EXPECT_EQ(third.get(), kept);
  EXPECT_EQ(third->image.data._buffer, b.data());
  set_string(third->header.frame_id, "camera_optical");
  EXPECT_EQ(third->header.frame_id, storage) << "the string's storage is reused";
}

TEST(LentSamplePool, ASampleOutlivesItsPoolAndLetsGoOfItsLeaseLast) {
  std::array<std::uint8_t, 16> buffer{};
  const auto lease = std::make_shared<int>(0);
  std::shared_ptr<const PatternFrame> held;
  {
    LentSamplePool<PatternFrame> pool(&image_bytes);
    auto m = pool.lend(buffer.data(), buffer.size(), lease);
    set_string(m->header.frame_id, "camera_optical");
    held = std::move(m);
  }
  EXPECT_EQ(lease.use_count(), 2) << "held after the pool is gone";
  EXPECT_STREQ(held->header.frame_id, "camera_optical");
  EXPECT_EQ(held->image.data._buffer, buffer.data());
  held.reset();  // frees the strings, never the lent bytes (ASan would say)
  EXPECT_EQ(lease.use_count(), 1);
}

}  // namespace
}  // namespace avs::runtime
