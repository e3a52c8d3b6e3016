// Figures over several runs of one scenario that differ only in the sensor noise seed
// (issue 19: every figure is the median of 5 seeds, with the spread). I/O-free.
#pragma once

#include <string>
#include <vector>

#include "avs/report/summary.hpp"

namespace avs::report {

/// Per figure (summary_fields()): the median, the smallest and the largest over the runs.
/// NaN (undefined) values are left out of each figure's statistics; a figure undefined in every
/// run stays undefined.
struct SeedSpread {
  Summary median, min, max;
  std::size_t runs = 0;
};

/// Throws ReportError for an empty list.
[[nodiscard]] SeedSpread across_seeds(const std::vector<Summary>& runs);

/// A text table of the accuracy and rate figures: figure | median | min | max | unit-carrying
/// key, for the terminal and docs (`markdown` true: a Markdown table).
[[nodiscard]] std::string format_seed_spread(const SeedSpread& spread, bool markdown = false);

}  // namespace avs::report
