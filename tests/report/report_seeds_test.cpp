// Median and spread of a scenario's figures over noise seeds (avs experiments --seeds).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "avs/report/run_data.hpp"
#include "avs/report/seeds.hpp"

namespace avs::report {
namespace {

TEST(Seeds, MedianAndSpreadPerFigure) {
  std::vector<Summary> runs(4);
  const double positions[] = {2.0, 1.0, 4.0, 3.0};
  for (std::size_t k = 0; k < runs.size(); ++k) {
    runs[k].position_error_mm_rms = positions[k];
    runs[k].flips = static_cast<double>(k);
    runs[k].centroid_error_px_rms = k == 2 ? 7.0 : kUndefined;  // defined in one run only
  }
  const SeedSpread s = across_seeds(runs);
  EXPECT_EQ(s.runs, 4u);
  EXPECT_DOUBLE_EQ(s.median.position_error_mm_rms, 2.5);  // even count: mean of the middle two
  EXPECT_DOUBLE_EQ(s.min.position_error_mm_rms, 1.0);
  EXPECT_DOUBLE_EQ(s.max.position_error_mm_rms, 4.0);
  EXPECT_DOUBLE_EQ(s.median.flips, 1.5);
  EXPECT_DOUBLE_EQ(s.median.centroid_error_px_rms, 7.0) << "undefined runs are left out";
  EXPECT_TRUE(std::isnan(s.median.orientation_error_deg_rms)) << "undefined everywhere";
  runs.pop_back();
  EXPECT_DOUBLE_EQ(across_seeds(runs).median.position_error_mm_rms, 2.0);  // odd count
  const std::string table = format_seed_spread(s);
  EXPECT_NE(table.find("4 seeds"), std::string::npos) << table;
  EXPECT_NE(table.find("position_error_mm_rms"), std::string::npos) << table;
  EXPECT_EQ(table.find("orientation_error_deg_rms "), std::string::npos) << "undefined: no row";
  EXPECT_THROW((void)across_seeds({}), ReportError);
}

}  // namespace
}  // namespace avs::report
