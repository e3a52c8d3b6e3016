// A run folder in, a report out: summary.json, the PNG figures and index.html, written into
// the run folder; plus the entry point of `avs report DIR`.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "avs/report/plots.hpp"
#include "avs/report/run_data.hpp"
#include "avs/report/summary.hpp"

namespace avs::report {

struct ReportOptions {
  PlotConfig plots;
};

struct Report {
  RunInfo info;
  std::vector<std::string> warnings;  ///< from load_run
  Summary summary;
  PlotResult plots;
  std::filesystem::path summary_json;
  std::filesystem::path index_html;
};

/// 1. load_run, 2. compute_summary -> summary.json, 3. make_plots, 4. index.html.
/// Throws ReportError for unreadable data (with file:line); a figure that gnuplot fails on is
/// listed in Report::plots.failed and in the page instead.
[[nodiscard]] Report make_report(const std::filesystem::path& dir,
                                 const ReportOptions& options = {});

/// The page: results table (paper beside ours), every figure made, every figure skipped or
/// failed with the reason, all figures of the summary, links to the data and scripts.
[[nodiscard]] std::string render_index_html(const RunInfo& info, const Summary& summary,
                                            const PlotResult& plots,
                                            const std::vector<std::string>& warnings = {});

/// `avs report DIR`: makes the report, prints the results table and where the page is.
/// Returns 0, or 1 on an error (printed to `err`) or when a figure failed.
int report_main(const std::filesystem::path& dir, std::ostream& out, std::ostream& err,
                const ReportOptions& options = {});
int report_main(const std::filesystem::path& dir);  ///< std::cout, std::cerr

/// `avs experiments --json`: one object keyed by scenario name, each value as to_json.
[[nodiscard]] std::string experiments_json(
    const std::vector<std::pair<std::string, Summary>>& runs);

}  // namespace avs::report
