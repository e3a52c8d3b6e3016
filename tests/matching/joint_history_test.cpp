// JointHistory: the head's angles at a depth image's stamp from the 1 kHz joint states.
#include "avs/matching/joint_history.hpp"

#include <gtest/gtest.h>

namespace avs::matching {
namespace {

TEST(JointHistory, InterpolatesBetweenTheSamplesAroundTheTime) {
  JointHistory h;
  h.add({0.000, 0.10, -0.20});
  h.add({0.001, 0.12, -0.18});
  const auto q = h.at(0.00025, 0.02);
  ASSERT_TRUE(q.has_value());
  EXPECT_DOUBLE_EQ(q->t_s, 0.00025);
  EXPECT_NEAR(q->pan_rad, 0.105, 1e-12);
  EXPECT_NEAR(q->tilt_rad, -0.195, 1e-12);
}

TEST(JointHistory, ExtrapolatesAtTheLastVelocityOnlyWithinTheLimit) {
  JointHistory h;
  h.add({0.000, 0.0, 0.0});
  h.add({0.001, 0.01, 0.0});
  const auto q = h.at(0.003, 0.005);
  ASSERT_TRUE(q.has_value());
  EXPECT_NEAR(q->pan_rad, 0.03, 1e-12);  // 10 rad/s for 2 ms more
  EXPECT_FALSE(h.at(0.010, 0.005).has_value()) << "9 ms past the newest sample";
  EXPECT_FALSE(JointHistory().at(0.0, 1.0).has_value()) << "empty history";
}

TEST(JointHistory, BeforeTheOldestGivesTheOldestWithinTheLimit) {
  JointHistory h;
  h.add({1.000, 0.5, 0.1});
  h.add({1.001, 0.6, 0.1});
  ASSERT_TRUE(h.at(0.999, 0.002).has_value());
  EXPECT_DOUBLE_EQ(h.at(0.999, 0.002)->pan_rad, 0.5);
  EXPECT_FALSE(h.at(0.9, 0.002).has_value());
}

TEST(JointHistory, TimeGoingBackStartsOverAndOldSamplesAreDropped) {
  JointHistory h(0.01);
  for (int i = 0; i <= 100; ++i) h.add({i * 0.001, i * 0.001, 0.0});
  EXPECT_LE(h.size(), 12u) << "only about keep_s of samples are kept";
  h.add({0.0005, 7.0, 0.0});  // a replay from the start
  EXPECT_EQ(h.size(), 1u);
  EXPECT_DOUBLE_EQ(h.at(0.0005, 0.0)->pan_rad, 7.0);
  h.add({0.0005, 8.0, 0.0});  // same stamp: replaces
  EXPECT_EQ(h.size(), 1u);
  EXPECT_DOUBLE_EQ(h.at(0.0005, 0.0)->pan_rad, 8.0);
}

TEST(JointHistory, KeepsASpanLongerThanItsFirstStorage) {
  // 1 s at 1 kHz: four times the storage it starts with, which grows to hold it all.
  JointHistory h(1.0);
  for (int i = 0; i <= 3000; ++i) h.add({i * 0.001, i * 0.001, -i * 0.001});
  EXPECT_GE(h.size(), 1000u);
  EXPECT_LE(h.size(), 1002u);
  const auto oldest = h.at(2.0015, 0.0);
  ASSERT_TRUE(oldest.has_value()) << "a stamp 1 s back is still inside the history";
  EXPECT_NEAR(oldest->pan_rad, 2.0015, 1e-9);
  EXPECT_NEAR(oldest->tilt_rad, -2.0015, 1e-9);
  EXPECT_NEAR(h.at(2.9995, 0.0)->pan_rad, 2.9995, 1e-9);
}

}  // namespace
}  // namespace avs::matching
