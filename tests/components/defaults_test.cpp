// Issue 13, "every default written once": walks every component registered in this program
// and checks that the parameters bound to a core Config (runtime/config_params.hpp) have the
// Config's defaults, and that the components with a core Config do bind it.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"

namespace avs::runtime {
namespace {

TEST(ComponentDefaults, BoundParametersHaveTheirCoreConfigsDefaults) {
  const auto all = ComponentRegistry::instance().all();
  ASSERT_FALSE(all.empty());
  std::set<std::string> bound;
  for (const RegisteredComponent* c : all) {
    if (!c->spec.default_mismatches) continue;
    bound.insert(c->spec.type);
    for (const std::string& name : c->spec.default_mismatches()) {
      ADD_FAILURE() << c->spec.type << ": parameter '" << name
                    << "' does not reproduce its core Config's default";
    }
  }
  // The components whose cores have a Config with defaults bind their parameters to it.
  for (const char* type : {"tracking", "matching", "decode", "servo_drive"}) {
    EXPECT_TRUE(bound.contains(type)) << type << " keeps a second list of defaults";
  }
}

// Issue 18: a parameter changed while the rig runs is checked against the spec's range before
// it is applied; a live number or list of numbers without one (a gain set to -1, a torque
// limit to 1e9) would go straight into the loop.
TEST(ComponentDefaults, EveryLiveNumberHasARange) {
  for (const RegisteredComponent* c : ComponentRegistry::instance().all()) {
    if (c->spec.type.rfind("test_", 0) == 0) continue;  // test components
    for (const ParamSpec& p : c->spec.parameters) {
      if (!p.dynamic) continue;
      if (p.type != ParamType::real && p.type != ParamType::integer &&
          p.type != ParamType::real_list) {
        continue;
      }
      EXPECT_TRUE(p.min.has_value() && p.max.has_value())
          << c->spec.type << ": live parameter '" << p.name << "' has no range";
    }
  }
}

struct Sample {
  double gain = 2.5;
  float limit = 0.3F;
  int count = 7;
  bool on = true;
  enum class Mode { a, b } mode = Mode::b;
  struct Pair {
    double v[2] = {1.0, 2.0};
    std::size_t size() const { return 2; }
    double& operator[](std::size_t i) { return v[i]; }
    const double& operator[](std::size_t i) const { return v[i]; }
  } list;
};

TEST(ConfigParams, SpecDefaultsComeFromTheConfigAndMakeFillsIt) {
  const auto params = ConfigParams<Sample>()
                          .real("gain", AVS_FIELD(gain), 0.0, 10.0, "", "")
                          .real("limit", AVS_FIELD(limit), 0.0, 1.0, "", "")
                          .integer("count", AVS_FIELD(count), 0, 100, "", "")
                          .boolean("on", AVS_FIELD(on), "")
                          .choice("mode", AVS_FIELD(mode),
                                  std::vector<std::pair<std::string, Sample::Mode>>{
                                      {"a", Sample::Mode::a}, {"b", Sample::Mode::b}},
                                  "")
                          .vector("list", AVS_FIELD(list), "", "");
  ASSERT_EQ(params.specs().size(), 6u);
  EXPECT_EQ(std::get<double>(params.specs()[0].default_value), 2.5);
  EXPECT_EQ(std::get<std::int64_t>(params.specs()[2].default_value), 7);
  EXPECT_EQ(std::get<std::string>(params.specs()[4].default_value), "b");
  EXPECT_EQ(std::get<std::vector<double>>(params.specs()[5].default_value),
            (std::vector<double>{1.0, 2.0}));
  EXPECT_TRUE(params.default_mismatches().empty());

  ParameterValues values;
  for (const auto& spec : params.specs()) values.set(spec.name, spec.default_value);
  values.set("gain", 4.0);
  values.set("mode", std::string("a"));
  values.set("list", std::vector<double>{3.0, 4.0});
  const Sample made = params.make(values);
  EXPECT_EQ(made.gain, 4.0);
  EXPECT_EQ(made.mode, Sample::Mode::a);
  EXPECT_EQ(made.list[1], 4.0);
  EXPECT_EQ(made.count, 7);
  values.set("list", std::vector<double>{1.0});
  EXPECT_THROW(params.make(values), Error) << "a list of the wrong size";
}

}  // namespace
}  // namespace avs::runtime
