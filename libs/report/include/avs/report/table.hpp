// Plain-text tables for the terminal (`avs demo`, `avs experiments`, `avs report`).
#pragma once

#include <string>
#include <vector>

#include "avs/report/paper.hpp"

namespace avs::report {

/// Columns padded to their widest cell; numeric-looking cells are right-aligned.
class TextTable {
 public:
  explicit TextTable(std::vector<std::string> headers) : headers_(std::move(headers)) {}
  /// Throws ReportError when the row's cell count differs from the header's.
  void add_row(std::vector<std::string> cells);
  [[nodiscard]] std::string render() const;

 private:
  std::vector<std::string> headers_;
  std::vector<std::vector<std::string>> rows_;
};

/// A figure for a table: "-" for NaN, integers without decimals, else 4 significant digits.
[[nodiscard]] std::string format_figure(double value);

/// Text for a Markdown table cell: '|' escaped.
[[nodiscard]] std::string markdown_cell(const std::string& text);

/// The columns of the results table, in order.
[[nodiscard]] const std::vector<std::string>& comparison_headers();

/// The results table of a run: figure | statistic | clock | paper | ours | unit | verdict |
/// section (comparison_headers()).
[[nodiscard]] std::string format_comparison_table(const std::string& scenario,
                                                  const Summary& summary);

/// The same table as GitHub-flavoured Markdown (for docs/experiments.md).
[[nodiscard]] std::string format_comparison_markdown(const std::string& scenario,
                                                     const Summary& summary);

/// What the table's clocks mean for this run, with its real-time factor: "Run: 3 s of
/// simulated time in 17.6 s of wall-clock time (real-time factor 0.17). Clock 'sim': ...".
[[nodiscard]] std::string format_run_clocks(const Summary& summary);

}  // namespace avs::report
