// Median and spread over seeds; see seeds.hpp.
#include "avs/report/seeds.hpp"

#include <algorithm>
#include <cmath>

#include "avs/report/run_data.hpp"
#include "avs/report/table.hpp"

namespace avs::report {

SeedSpread across_seeds(const std::vector<Summary>& runs) {
  if (runs.empty()) throw ReportError("across_seeds: no runs");
  SeedSpread s;
  s.runs = runs.size();
  s.median = s.min = s.max = runs.front();
  for (const SummaryField& field : summary_fields()) {
    std::vector<double> values;
    for (const Summary& run : runs) {
      const double v = run.*field.member;
      if (!std::isnan(v)) values.push_back(v);
    }
    if (values.empty()) {
      s.median.*field.member = s.min.*field.member = s.max.*field.member = kUndefined;
      continue;
    }
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    // The median of an even count is the mean of the middle two.
    s.median.*field.member = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
    s.min.*field.member = values.front();
    s.max.*field.member = values.back();
  }
  return s;
}

std::string format_seed_spread(const SeedSpread& spread, bool markdown) {
  // The figures that depend on the seed: rates, errors, flips, view and centroid.
  static const char* const kKeys[] = {"pose_rate_hz",
                                      "position_error_mm_rms",
                                      "position_error_mm_p99",
                                      "orientation_error_deg_rms",
                                      "orientation_error_deg_rms_excluding_flips",
                                      "flips",
                                      "in_view_fraction",
                                      "centroid_error_px_rms"};
  const std::string runs = std::to_string(spread.runs) + " seeds";
  TextTable table({"figure (" + runs + ")", "median", "min", "max", "key"});
  std::string md = "| figure (" + runs + ") | median | min | max | key |\n|---|---|---|---|---|\n";
  for (const char* key : kKeys) {
    const SummaryField& field = summary_field(key);
    const double median = spread.median.*field.member;
    if (std::isnan(median)) continue;
    const std::string a = format_figure(median), b = format_figure(spread.min.*field.member),
                      c = format_figure(spread.max.*field.member);
    table.add_row({field.description, a, b, c, key});
    md += std::string("| ") + field.description + " | " + a + " | " + b + " | " + c + " | `" + key +
          "` |\n";
  }
  return markdown ? md : table.render();
}

}  // namespace avs::report
