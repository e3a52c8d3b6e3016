// The paper's figures (Sec. 7 of "Development of an Active High-Speed 3-D Vision System"),
// as stated there, each with its section, and the table that puts ours beside them.
#pragma once

#include <string>
#include <vector>

#include "avs/report/summary.hpp"

namespace avs::report {

/// One figure the paper states. These are facts from the paper, not results of ours.
struct PaperFigure {
  const char* scenario;  ///< "tracking", "no_tracking", "ken", "cube", "cylinder", "init", ...
  const char* key;       ///< the Summary key ours is compared with
  const char* label;     ///< "depth update rate"
  const char* paper;     ///< as stated: "500", "about 1.5", "< 1.5", "148"
  const char* unit;      ///< "Hz", "ms", ""
  const char* section;   ///< "7.2.1"
  const char* source;    ///< where in the section, in the paper's words
};

/// Every figure of Sec. 7 (and Sec. 8's 500 Hz claim) in one table.
[[nodiscard]] const std::vector<PaperFigure>& paper_figures();

/// The scenarios `avs experiments` knows (7.1.1 ... 7.4), plus "demo" (the ken on the
/// manipulator with tracking and matching: the figures of "tracking" and "ken").
[[nodiscard]] const std::vector<std::string>& known_scenarios();

/// One line of the results table.
struct ComparisonRow {
  std::string label;
  std::string unit;
  std::string paper;  ///< "-" when the paper states no number for it
  double ours = kUndefined;
  std::string section;  ///< "-" when not from the paper
  std::string key;      ///< Summary key of `ours`
};

/// The paper's figures for `scenario` beside ours, then our other main figures (rates,
/// stage times, pose and tracking errors) that the run has data for.
[[nodiscard]] std::vector<ComparisonRow> comparison_rows(const std::string& scenario,
                                                         const Summary& summary);

}  // namespace avs::report
