#include "avs/servo/register_map.hpp"

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

TEST(RegisterMap, ThirtyTwoBitWordOrders) {
  RegisterSpec spec{true, 8, 2, true, WordOrder::high_first, 1.0};
  std::uint16_t regs[2];
  write_counts(spec, -2, regs);
  EXPECT_EQ(regs[0], 0xFFFF);
  EXPECT_EQ(regs[1], 0xFFFE);
  EXPECT_EQ(read_counts(spec, regs), -2);
  spec.word_order = WordOrder::low_first;
  write_counts(spec, 0x00085555, regs);  // Kinco example: sent as 5555, 0008
  EXPECT_EQ(regs[0], 0x5555);
  EXPECT_EQ(regs[1], 0x0008);
  EXPECT_EQ(read_counts(spec, regs), 0x00085555);
}

TEST(RegisterMap, ScaleRoundsAndSaturates) {
  const RegisterSpec torque{true, 1, 1, true, WordOrder::high_first, 1.91 / 1000};
  EXPECT_EQ(to_counts(torque, 1.91), 1000);
  EXPECT_EQ(to_counts(torque, 1e6), 32767);
  EXPECT_EQ(to_counts(torque, -1e6), -32768);
  EXPECT_NEAR(to_si(torque, 500), 0.955, 1e-12);
}

TEST(RegisterMap, DefaultMapIsValidAndOverlapsAreRejected) {
  RegisterMap map = default_register_map(1.91, 1e-5);
  EXPECT_NO_THROW(validate(map));
  EXPECT_EQ(map.register_count(), 16);
  map[Signal::velocity_actual].address = 9;  // overlaps position_actual (8-9)
  EXPECT_THROW(validate(map), std::invalid_argument);
}

TEST(RegisterMap, SignalNamesRoundTrip) {
  for (std::size_t i = 0; i < signal_count; ++i) {
    const auto s = static_cast<Signal>(i);
    EXPECT_EQ(signal_from_name(signal_name(s)), s);
  }
  EXPECT_FALSE(signal_from_name("torque"));
}

}  // namespace
}  // namespace avs::servo
