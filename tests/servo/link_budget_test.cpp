#include "avs/servo/link_budget.hpp"

#include <gtest/gtest.h>

namespace avs::servo {
namespace {

// Reference table 1.3: 115200 baud, 11-bit characters, 0x17: 4010 us wire, 7510 us with the
// spec's 1.75 ms gaps per axis; two axes top out at ~67 Hz.
TEST(LinkBudget, MatchesTheReferenceArithmetic) {
  const SerialLine line{115200, 'E', 8, 1};
  const ExchangeShape shape{3, 9, true};
  const LinkBudget b = rtu_link_budget(line, shape, 2, 0.0);
  EXPECT_EQ(b.bytes_per_axis, 42);
  EXPECT_DOUBLE_EQ(b.char_bits, 11);
  EXPECT_NEAR(b.seconds_per_axis, 7.510e-3, 5e-6);
  EXPECT_NEAR(b.max_cycle_rate_hz, 66.6, 0.1);
}

TEST(LinkBudget, SlowBaudUsesThreeAndAHalfCharacters) {
  const LinkBudget b = rtu_link_budget({9600, 'N', 8, 1}, {3, 9, true}, 1, 0.0);
  EXPECT_NEAR(b.gap_s, 3.5 * 10.0 / 9600, 1e-12);
}

TEST(LinkBudget, RefusesARateTheLineCannotCarry) {
  const SerialLine line{115200, 'E', 8, 1};
  const std::string refusal = check_rtu_cycle_rate(line, {3, 9, true}, 2, 0.0005, 1000.0);
  ASSERT_FALSE(refusal.empty());
  EXPECT_NE(refusal.find("at most"), std::string::npos) << refusal;
  EXPECT_EQ(refusal.find('\n'), std::string::npos);
  EXPECT_TRUE(check_rtu_cycle_rate(line, {3, 9, true}, 2, 0.0005, 50.0).empty());
  // Separate write + read costs more than one 0x17.
  EXPECT_FALSE(check_rtu_cycle_rate(line, {3, 9, false}, 2, 0.0005, 50.0).empty());
}

}  // namespace
}  // namespace avs::servo
