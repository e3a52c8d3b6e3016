#include <gtest/gtest.h>

#include "avs/runtime/parameters.hpp"

namespace avs::runtime {
namespace {

TEST(ParamSpec, RealRangeMessageNamesRangeUnitAndValue) {
  const auto spec = ParamSpec::real("rate_hz", 10.0, 0.1, 10000.0, "Hz", "rate");
  EXPECT_EQ(spec.check(ParamValue{0.0}), "expected a number in [0.1, 10000] Hz, got 0");
  EXPECT_EQ(spec.check(ParamValue{5.0}), "");
  EXPECT_EQ(spec.check(ParamValue{std::int64_t{5}}), "");  // integers are numbers
  EXPECT_EQ(spec.check(ParamValue{10000.0}), "");          // bounds are inclusive
  EXPECT_EQ(spec.check(ParamValue{std::string("fast")}),
            "expected a number in [0.1, 10000] Hz, got 'fast'");
}

TEST(ParamSpec, IntegerRejectsRealsAndOutOfRange) {
  const auto spec = ParamSpec::integer("count", 3, 0.0, std::nullopt, "", "count");
  EXPECT_EQ(spec.check(ParamValue{std::int64_t{0}}), "");
  EXPECT_EQ(spec.check(ParamValue{std::int64_t{-1}}), "expected an integer >= 0, got -1");
  EXPECT_EQ(spec.check(ParamValue{2.5}), "expected an integer >= 0, got 2.5");
}

TEST(ParamSpec, BooleanStringAndChoices) {
  EXPECT_EQ(ParamSpec::boolean("on", true, "").check(ParamValue{std::string("yes")}),
            "expected true or false, got 'yes'");
  EXPECT_EQ(ParamSpec::boolean("on", true, "").check(ParamValue{false}), "");
  const auto mode = ParamSpec::string("mode", "fast", "", {"fast", "slow"});
  EXPECT_EQ(mode.check(ParamValue{std::string("slow")}), "");
  EXPECT_EQ(mode.check(ParamValue{std::string("medium")}),
            "expected one of 'fast', 'slow', got 'medium'");
  EXPECT_EQ(ParamSpec::string("label", "", "").check(ParamValue{std::string("anything")}), "");
}

TEST(ParamSpec, RealListChecksEachElement) {
  auto spec = ParamSpec::real_list("gains", {1.0}, "", "gains");
  spec.min = 0.0;
  EXPECT_EQ(spec.check(ParamValue{std::vector<double>{1.0, 2.0}}), "");
  EXPECT_EQ(spec.check(ParamValue{std::vector<double>{1.0, -2.0}}),
            "expected a list of numbers >= 0, got -2 at index 1");
  EXPECT_EQ(spec.check(ParamValue{1.0}), "expected a list of numbers >= 0, got 1");
}

TEST(ParamValue, ToStringAndTypeOf) {
  EXPECT_EQ(to_string(ParamValue{true}), "true");
  EXPECT_EQ(to_string(ParamValue{std::int64_t{-3}}), "-3");
  EXPECT_EQ(to_string(ParamValue{0.1}), "0.1");
  EXPECT_EQ(to_string(ParamValue{std::string("x y")}), "x y");
  EXPECT_EQ(to_string(ParamValue{std::vector<double>{1.0, 2.5}}), "[1, 2.5]");
  EXPECT_EQ(type_of(ParamValue{std::vector<double>{}}), ParamType::real_list);
  EXPECT_EQ(type_of(ParamValue{std::int64_t{1}}), ParamType::integer);
  EXPECT_EQ(to_string(ParamType::real), "number");
}

TEST(ParamSpec, FactoriesStoreDefaults) {
  const auto spec = ParamSpec::integer("n", 4, 1.0, 8.0, "px", "size");
  EXPECT_EQ(spec.type, ParamType::integer);
  EXPECT_EQ(std::get<std::int64_t>(spec.default_value), 4);
  EXPECT_EQ(spec.unit, "px");
  EXPECT_EQ(spec.check(spec.default_value), "");
}

}  // namespace
}  // namespace avs::runtime
