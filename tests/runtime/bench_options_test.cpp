// Issue 20 section 2: a benchmark's bad number is refused naming the benchmark, the option and
// its range (it was "avs: stod"), and an unknown option is named.
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/bench/report.hpp"

namespace avs::bench {
namespace {

std::string refusal(const std::vector<std::string>& args) {
  try {
    Options options("servo", args);
    (void)options.number("--rate", 1000.0, 1.0, 100000.0);
    (void)options.integer("--frames", 300, 10, 1000000);
    options.finish();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(BenchOptions, ReadsValuesInEitherSpellingAndKeepsDefaults) {
  Options options("servo", {"--rate=250.5", "--frames", "40"});
  EXPECT_EQ(options.number("--rate", 1000.0, 1.0, 100000.0), 250.5);
  EXPECT_EQ(options.integer("--frames", 300, 10, 1000000), 40);
  EXPECT_EQ(options.number("--seconds", 3.0, 0.1, 10.0), 3.0);
  EXPECT_NO_THROW(options.finish());
}

TEST(BenchOptions, BadNumbersAreRefusedWithTheOptionAndItsRange) {
  const std::string rate = "avs bench servo: --rate wants a number in [1, 100000], got '";
  EXPECT_EQ(refusal({"--rate", "abc"}), rate + "abc'");
  EXPECT_EQ(refusal({"--rate", "12x"}), rate + "12x'");
  EXPECT_EQ(refusal({"--rate", "nan"}), rate + "nan'");
  EXPECT_EQ(refusal({"--rate", "inf"}), rate + "inf'");
  EXPECT_EQ(refusal({"--rate", "1e400"}), rate + "1e400'");
  EXPECT_EQ(refusal({"--rate", "0"}), rate + "0'");
  EXPECT_EQ(refusal({"--rate="}), rate + "'");
  const std::string frames = "avs bench servo: --frames wants an integer in [10, 1000000], got '";
  EXPECT_EQ(refusal({"--frames", "2.5"}), frames + "2.5'");
  EXPECT_EQ(refusal({"--frames", "99999999999999999999"}), frames + "99999999999999999999'");
  EXPECT_EQ(refusal({"--frames", "-5"}), frames + "-5'");
}

TEST(BenchOptions, UnknownOrValuelessOptionsAreNamed) {
  EXPECT_EQ(refusal({"--rat", "5"}),
            "avs bench servo: unknown option --rat (expected --rate, --frames)");
  EXPECT_EQ(refusal({"--rate"}), "avs bench servo: --rate needs a value");
  EXPECT_EQ(refusal({"5"}), "avs bench servo: expected an option (--name value), got '5'");
}

TEST(BenchOptions, HelpListsTheOptionsAskedForWithRangesAndDefaultsInsteadOfRunning) {
  Options options("servo", {"--help"});
  options.number("--seconds", 3.0, 0.1, 3600.0);
  options.integer("--frames", 300, 10, 1000000);
  options.text("--model", "ken");
  std::string help;
  try {
    options.finish();
  } catch (const HelpRequested& h) {
    help = h.what();
  }
  EXPECT_EQ(help,
            "avs bench servo options (as --key value or --key=value):\n"
            "  --seconds N                 a number in [0.1, 3600] (default 3)\n"
            "  --frames N                  an integer in [10, 1000000] (default 300)\n"
            "  --model TEXT                (default ken)\n");
  // A benchmark that answers --help itself (flag("--help")) gets no HelpRequested.
  Options own("bag", {"-h"}, {"--keep"});
  EXPECT_TRUE(own.flag("-h"));
  EXPECT_NO_THROW(own.finish());
}

}  // namespace
}  // namespace avs::bench
