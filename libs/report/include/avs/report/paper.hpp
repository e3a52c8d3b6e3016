// The paper's figures (Sec. 7 of "Development of an Active High-Speed 3-D Vision System"),
// as stated there, each with its section, and the table that puts ours beside them.
#pragma once

#include <string>
#include <vector>

#include "avs/report/summary.hpp"

namespace avs::report {

/// The test a figure of ours passes or fails against the paper: below a stated limit ("< 2
/// ms"), or at least a stated rate or outcome. Rates pass within kRateTolerance of the paper's.
struct PaperLimit {
  enum class Kind { none, below, at_least };
  Kind kind = Kind::none;
  double value = 0.0;
};
inline constexpr double kRateTolerance = 0.01;  ///< one missed update in a hundred
[[nodiscard]] PaperLimit below(double value);
[[nodiscard]] PaperLimit at_least(double value);
/// A rate of the paper's: at least (1 - kRateTolerance) times it.
[[nodiscard]] PaperLimit rate_of(double paper_hz);

/// "pass (< 2)", "FAIL (>= 495)", "-" for a NaN figure, "" without a limit.
[[nodiscard]] std::string verdict(const PaperLimit& limit, double ours);

/// One figure the paper states. These are facts from the paper, not results of ours.
struct PaperFigure {
  const char* scenario;  ///< "tracking", "no_tracking", "ken", "cube", "cylinder", "init", ...
  const char* key;       ///< the Summary key ours is compared with
  const char* label;     ///< "depth update rate"
  const char* paper;     ///< as stated: "500", "about 1.5", "< 1.5", "148"
  const char* unit;      ///< "Hz", "ms", ""
  const char* section;   ///< "7.2.1"
  const char* source;    ///< where in the section, in the paper's words
  PaperLimit limit{};    ///< what ours must meet to pass; none when the paper gives no limit
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
  std::string section;    ///< "-" when not from the paper
  std::string key;        ///< Summary key of `ours`
  std::string statistic;  ///< of the run's updates: "median", "p99", "RMS", "mean rate", ...
  std::string clock;      ///< "sim", "wall" or "-" (figure_clock_name)
  std::string verdict;    ///< against the paper's limit (verdict()); "" without one
};

/// The paper's figures for `scenario` beside ours, then our other main figures (rates,
/// stage times, pose and tracking errors) that the run has data for.
[[nodiscard]] std::vector<ComparisonRow> comparison_rows(const std::string& scenario,
                                                         const Summary& summary);

}  // namespace avs::report
