// SamplePool (Publisher::loan): a sample comes back once nobody else holds it, never while a
// subscriber does; set_string reuses a string's storage when it fits.
#include <gtest/gtest.h>

#include "avs/runtime/sample.hpp"
#include "std_msgs.h"

namespace avs::runtime {
namespace {

using msgs::std_msgs::String;

TEST(SamplePool, ReusesASampleOnlyOnceNobodyElseHoldsIt) {
  SamplePool<String> pool(2);
  std::shared_ptr<const String> held = pool.acquire();  // a subscriber keeps it
  const String* first = held.get();
  const auto second = pool.acquire();
  EXPECT_NE(second.get(), first);  // the held one is not handed out again
  held.reset();                    // the subscriber lets it go
  EXPECT_EQ(pool.acquire().get(), first);
}

TEST(SamplePool, BeyondItsLimitItHandsOutFreshSamplesItDoesNotKeep) {
  SamplePool<String> pool(1);
  const auto kept = pool.acquire();
  std::shared_ptr<String> extra = pool.acquire();  // the kept one is held: a fresh one
  EXPECT_NE(extra.get(), kept.get());
  EXPECT_EQ(extra.use_count(), 1);  // the pool (full) does not keep it: freed when let go
}

TEST(SetString, ReusesTheStorageWhenTheNewValueFitsAndGrowsOtherwise) {
  char* field = nullptr;
  set_string(field, "camera_optical");
  char* const storage = field;
  set_string(field, "camera");  // shorter: same storage
  EXPECT_EQ(field, storage);
  EXPECT_STREQ(field, "camera");
  set_string(field, "camera_optical_frame");  // longer than what is there now: new storage
  EXPECT_STREQ(field, "camera_optical_frame");
  dds_free(field);
}

}  // namespace
}  // namespace avs::runtime
