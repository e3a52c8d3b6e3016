// Figures of one scenario under several sensor profiles; see profiles.hpp.
#include "avs/report/profiles.hpp"

#include <algorithm>

#include "avs/report/paper.hpp"
#include "avs/report/run_data.hpp"
#include "avs/report/table.hpp"

namespace avs::report {

std::string format_profiles_side_by_side(const std::string& scenario,
                                         const std::vector<ProfileSummary>& profiles,
                                         bool markdown) {
  if (profiles.empty()) throw ReportError("format_profiles_side_by_side: no profiles");
  // Per profile its rows; the table's rows are the union by key, in first-seen order.
  std::vector<std::vector<ComparisonRow>> rows_by_profile;
  std::vector<ComparisonRow> rows;
  for (const auto& [name, summary] : profiles) {
    rows_by_profile.push_back(comparison_rows(scenario, summary));
    for (const ComparisonRow& row : rows_by_profile.back()) {
      if (std::none_of(rows.begin(), rows.end(),
                       [&](const ComparisonRow& r) { return r.key == row.key; })) {
        rows.push_back(row);
      }
    }
  }
  std::vector<std::string> headers{"figure", "statistic", "clock", "paper"};
  for (const auto& profile : profiles) headers.push_back(profile.first);
  headers.emplace_back("unit");
  for (const auto& profile : profiles) headers.push_back("verdict " + profile.first);
  headers.emplace_back("section");

  std::vector<std::vector<std::string>> cells;
  for (const ComparisonRow& row : rows) {
    std::vector<std::string> line{row.label, row.statistic, row.clock, row.paper};
    std::vector<std::string> verdicts;
    for (const auto& profile_rows : rows_by_profile) {
      const auto it = std::find_if(profile_rows.begin(), profile_rows.end(),
                                   [&](const ComparisonRow& r) { return r.key == row.key; });
      line.push_back(it == profile_rows.end() ? "-" : format_figure(it->ours));
      verdicts.push_back(it == profile_rows.end() || it->verdict.empty() ? "-" : it->verdict);
    }
    line.push_back(row.unit);
    line.insert(line.end(), verdicts.begin(), verdicts.end());
    line.push_back(row.section);
    cells.push_back(std::move(line));
  }

  if (!markdown) {
    TextTable table(headers);
    for (auto& line : cells) table.add_row(std::move(line));
    return table.render();
  }
  std::string out = "|";
  std::string rule = "|";
  for (std::size_t c = 0; c < headers.size(); ++c) {
    out += " " + headers[c] + " |";
    const bool value_column = c == 3 || (c >= 4 && c < 4 + profiles.size());
    rule += value_column ? "---:|" : "---|";
  }
  out += "\n" + rule + "\n";
  for (const auto& line : cells) {
    out += "|";
    for (const std::string& text : line) out += " " + markdown_cell(text) + " |";
    out += "\n";
  }
  return out;
}

}  // namespace avs::report
