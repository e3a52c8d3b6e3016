#include <gtest/gtest.h>

#include <cmath>

#include "avs/runtime/config_params.hpp"
#include "avs/runtime/parameter_messages.hpp"
#include "avs/runtime/parameters.hpp"
#include "avs/runtime/sample.hpp"

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
  EXPECT_EQ(to_string(ParamType::real), "double");  // ROS 2's names, as avs param prints them
  EXPECT_EQ(to_string(ParamType::real_list), "double array");
  EXPECT_EQ(to_string(ParamType::boolean), "boolean");
}

TEST(ParamSpec, FactoriesStoreDefaults) {
  const auto spec = ParamSpec::integer("n", 4, 1.0, 8.0, "px", "size");
  EXPECT_EQ(spec.type, ParamType::integer);
  EXPECT_EQ(std::get<std::int64_t>(spec.default_value), 4);
  EXPECT_EQ(spec.unit, "px");
  EXPECT_EQ(spec.check(spec.default_value), "");
}

TEST(ParamText, ReadWithTheParametersType) {
  EXPECT_EQ(parse_param_text(ParamType::integer, "30"), ParamValue{std::int64_t{30}});
  EXPECT_EQ(parse_param_text(ParamType::real, "30"), ParamValue{30.0});
  EXPECT_EQ(parse_param_text(ParamType::real, "0.5"), ParamValue{0.5});
  EXPECT_EQ(parse_param_text(ParamType::boolean, "true"), ParamValue{true});
  EXPECT_EQ(parse_param_text(ParamType::real_list, "[1, 2.5]"),
            (ParamValue{std::vector<double>{1.0, 2.5}}));
  EXPECT_EQ(parse_param_text(ParamType::real_list, "[]"), ParamValue{std::vector<double>{}});
  // Text that is not of the type stays text, so that check() says what was expected.
  EXPECT_EQ(parse_param_text(ParamType::integer, "3.5"), ParamValue{std::string("3.5")});
  EXPECT_EQ(parse_param_text(ParamType::boolean, "yes"), ParamValue{std::string("yes")});
  EXPECT_EQ(parse_param_text(ParamType::real_list, "[1, x]"), ParamValue{std::string("[1, x]")});
}

TEST(ParamText, YamlTextReadsBackAsTheSameValue) {
  EXPECT_EQ(to_yaml_text(ParamValue{30.0}), "30.0");  // a float to YAML, not an integer
  EXPECT_EQ(to_yaml_text(ParamValue{0.05}), "0.05");
  EXPECT_EQ(to_yaml_text(ParamValue{std::int64_t{-1}}), "-1");
  EXPECT_EQ(to_yaml_text(ParamValue{std::string("rolling")}), "rolling");
  EXPECT_EQ(to_yaml_text(ParamValue{std::string("")}), "''");
  EXPECT_EQ(to_yaml_text(ParamValue{std::string("true")}), "'true'");
  EXPECT_EQ(to_yaml_text(ParamValue{std::string("10")}), "'10'");
  EXPECT_EQ(to_yaml_text(ParamValue{std::string("pan,tilt")}), "'pan,tilt'");
  EXPECT_EQ(to_yaml_text(ParamValue{std::string("it's")}), "'it''s'");
  EXPECT_EQ(to_yaml_text(ParamValue{std::vector<double>{1, 2.5}}), "[1, 2.5]");
  EXPECT_EQ(format_number(1e7), "10000000");  // whole numbers as integers
  EXPECT_EQ(format_number(1e-6), "1e-06");
  // A range's bound of 1e15 (sim_scene's seed) printed "1e+15" (issue 18 section 4).
  EXPECT_EQ(format_number(1e15), "1000000000000000");
  EXPECT_EQ(format_number(-9007199254740992.0), "-9007199254740992");
}

TEST(ParamSpec, LiveMarksDynamicAndFloatDefaultsKeepTheirDecimal) {
  EXPECT_FALSE(ParamSpec::real("a", 1, 0, 2, "", "").dynamic);
  EXPECT_TRUE(ParamSpec::real("a", 1, 0, 2, "", "").live().dynamic);
  struct Config {
    float depth_m = 0.05f;
    int n = 3;
  };
  const auto params = ConfigParams<Config>()
                          .real("depth_m", AVS_FIELD(depth_m), 0.0, 1.0, "m", "")
                          .live()
                          .integer("n", AVS_FIELD(n), 0, 9, "", "");
  ASSERT_EQ(params.specs().size(), 2u);
  EXPECT_TRUE(params.specs()[0].dynamic);
  EXPECT_FALSE(params.specs()[1].dynamic);
  EXPECT_EQ(std::get<double>(params.specs()[0].default_value), 0.05);
  EXPECT_TRUE(params.default_mismatches().empty());
}

TEST(ParameterMessages, DescriptorSaysTypeRangeUnitAndDynamic) {
  auto d = make_sample<msgs::rcl_interfaces::ParameterDescriptor>();
  to_descriptor(ParamSpec::integer("threshold_psi", 10, 0, 255, "", "psi").live(), *d);
  EXPECT_EQ(d->type, 2);  // PARAMETER_INTEGER
  EXPECT_FALSE(d->read_only);
  ASSERT_EQ(d->integer_range._length, 1u);
  EXPECT_EQ(d->integer_range._buffer[0].from_value, 0);
  EXPECT_EQ(d->integer_range._buffer[0].to_value, 255);
  auto r = make_sample<msgs::rcl_interfaces::ParameterDescriptor>();
  to_descriptor(ParamSpec::real("rate_hz", 100, 0.001, std::nullopt, "Hz", "rate"), *r);
  EXPECT_TRUE(r->read_only);  // restart-only
  EXPECT_EQ(get_string(r->description), "rate [Hz]");
  ASSERT_EQ(r->floating_point_range._length, 1u);
  EXPECT_TRUE(std::isinf(r->floating_point_range._buffer[0].to_value));
  auto v = make_sample<msgs::rcl_interfaces::ParameterValue>();
  to_message(ParamValue{std::vector<double>{1, 2}}, *v);
  EXPECT_EQ(from_message(*v), (ParamValue{std::vector<double>{1, 2}}));
  EXPECT_EQ(parameter_service_node("rq/rig/decode/set_parametersRequest"), "/rig/decode");
  EXPECT_EQ(parameter_service_node("rt/decode/set_parametersRequest"), "");
}

}  // namespace
}  // namespace avs::runtime
