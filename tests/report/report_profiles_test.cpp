// One scenario under two sensor profiles, side by side (avs experiments --profile both).
#include <gtest/gtest.h>

#include <string>

#include "avs/report/profiles.hpp"
#include "avs/report/run_data.hpp"

namespace avs::report {
namespace {

// The line of `table` that starts with `label`.
std::string line_of(const std::string& table, const std::string& label) {
  const auto at = table.find("\n" + label);
  if (at == std::string::npos) return {};
  return table.substr(at + 1, table.find('\n', at + 1) - at - 1);
}

TEST(Profiles, EachProfileInItsOwnColumnOnTheSameRows) {
  Summary realistic;
  realistic.position_error_mm_rms = 2.26;
  realistic.flips = 0.0;
  Summary ideal;
  ideal.position_error_mm_rms = 2.3;
  ideal.flips = 0.0;
  ideal.centroid_error_px_rms = 15.07;  // ideal only: its row shows "-" for realistic
  const std::string table =
      format_profiles_side_by_side("ken", {{"realistic", realistic}, {"ideal", ideal}});
  const std::string header = table.substr(0, table.find('\n'));
  ASSERT_LT(header.find("realistic"), header.find("ideal")) << table;
  EXPECT_NE(header.find("verdict realistic"), std::string::npos) << table;

  const std::string position = line_of(table, "position error");
  ASSERT_FALSE(position.empty()) << table;
  EXPECT_LT(position.find("2.26"), position.find("2.3 ")) << position;
  const std::string centroid = line_of(table, "image centroid to image centre");
  ASSERT_FALSE(centroid.empty()) << table;
  EXPECT_NE(centroid.find(" - "), std::string::npos) << centroid;
  EXPECT_NE(centroid.find("15.07"), std::string::npos) << centroid;

  const std::string md =
      format_profiles_side_by_side("ken", {{"realistic", realistic}, {"ideal", ideal}}, true);
  EXPECT_EQ(md.rfind("| figure | statistic | clock | paper | realistic | ideal | unit |", 0), 0u)
      << md;
  EXPECT_NE(md.find("|---|---|---|---:|---:|---:|---|"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2.26 | 2.3 |"), std::string::npos) << md;
  EXPECT_THROW((void)format_profiles_side_by_side("ken", {}), ReportError);
}

}  // namespace
}  // namespace avs::report
