// One scenario run under several sensor profiles (issue 19: `avs experiments --profile both`),
// its figures side by side. I/O-free.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "avs/report/summary.hpp"

namespace avs::report {

/// A profile's name ("realistic", "ideal") and the scenario's figures under it.
using ProfileSummary = std::pair<std::string, Summary>;

/// The results table with one value column and one verdict column per profile:
/// figure | statistic | clock | paper | <profile>... | unit | verdict <profile>... | section.
/// Rows are comparison_rows() of the first profile, then any row only a later profile has; a
/// figure a profile has no data for is "-". `markdown` true: a Markdown table. Throws
/// ReportError for an empty list.
[[nodiscard]] std::string format_profiles_side_by_side(const std::string& scenario,
                                                       const std::vector<ProfileSummary>& profiles,
                                                       bool markdown = false);

}  // namespace avs::report
