#include "avs/report/report.hpp"

#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

#include "avs/report/paper.hpp"
#include "avs/report/table.hpp"
#include "avs/runtime/text.hpp"

namespace avs::report {
namespace {

namespace fs = std::filesystem;

void write_file(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::trunc);
  out << text;
  if (!out) throw ReportError(file.string() + ": write failed");
}

const char* const kPaperNote =
    "paper: the authors' hardware (Sec. 2: Xeon E5-1630v4, GeForce GTX 1080 Ti, real optics); "
    "ours: this run, simulated scene, times measured on this machine.";

const char* const kStyle =
    R"(body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #ccc;padding:.3em .6em}
th{background:#f0f0f0;text-align:left}td.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:2em 0}figure img{max-width:100%;border:1px solid #ddd}
figcaption{color:#444;margin-top:.4em}.warn{color:#a00}td.fail{color:#a00;font-weight:bold}
td.pass{color:#070}code{background:#f4f4f4;padding:0 .2em})";

}  // namespace

std::string render_index_html(const RunInfo& info, const Summary& summary, const PlotResult& plots,
                              const std::vector<std::string>& warnings) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<title>avs report: " << runtime::escape_markup(info.scenario) << "</title>\n<style>\n"
    << kStyle << "\n</style>\n</head>\n<body>\n"
    << "<h1>avs report: " << runtime::escape_markup(info.scenario) << "</h1>\n"
    << "<p>Target <b>" << runtime::escape_markup(info.object) << "</b> (symmetry <code>"
    << runtime::escape_markup(info.symmetry) << "</code>), " << format_figure(summary.frames)
    << " depth updates over " << format_figure(summary.duration_s) << " s of simulation time";
  if (std::isfinite(summary.real_time_factor)) {
    h << " (" << format_figure(summary.wall_duration_s) << " s of wall-clock time, real-time "
      << "factor " << format_figure(summary.real_time_factor) << ")";
  }
  h << ". Every number and figure below is computed from this folder's "
       "<a href=\"frames.csv\">frames.csv</a> by <code>avs report</code>; the paper's column "
       "quotes Sec. 7 of the paper.</p>\n";
  if (!info.notes.empty()) h << "<p>" << runtime::escape_markup(info.notes) << "</p>\n";
  for (const std::string& warning : warnings) {
    h << "<p class=\"warn\">" << runtime::escape_markup(warning) << "</p>\n";
  }

  // 1. Results: the paper beside ours.
  h << "<h2>Results</h2>\n<p>" << runtime::escape_markup(format_run_clocks(summary))
    << "</p>\n<table>\n<tr>";
  for (const std::string& header : comparison_headers()) h << "<th>" << header << "</th>";
  h << "</tr>\n";
  for (const ComparisonRow& row : comparison_rows(info.scenario, summary)) {
    const char* verdict_class = row.verdict.rfind("FAIL", 0) == 0   ? " class=\"fail\""
                                : row.verdict.rfind("pass", 0) == 0 ? " class=\"pass\""
                                                                    : "";
    h << "<tr><td>" << runtime::escape_markup(row.label) << "</td><td>"
      << runtime::escape_markup(row.statistic) << "</td><td>" << runtime::escape_markup(row.clock)
      << "</td><td class=\"num\">" << runtime::escape_markup(row.paper) << "</td><td class=\"num\">"
      << format_figure(row.ours) << "</td><td>" << runtime::escape_markup(row.unit) << "</td><td"
      << verdict_class << ">" << runtime::escape_markup(row.verdict.empty() ? "-" : row.verdict)
      << "</td><td>" << runtime::escape_markup(row.section) << "</td></tr>\n";
  }
  h << "</table>\n<p>" << runtime::escape_markup(kPaperNote) << "</p>\n";

  // 2. Figures.
  h << "<h2>Figures</h2>\n";
  for (const Plot& plot : plots.made) {
    h << "<figure id=\"" << runtime::escape_markup(plot.png) << "\">\n<h3>"
      << runtime::escape_markup(plot.title) << "</h3>\n<img src=\""
      << runtime::escape_markup(plot.png) << "\" alt=\"" << runtime::escape_markup(plot.title)
      << "\">\n<figcaption>" << runtime::escape_markup(plot.caption) << " Made by <a href=\""
      << runtime::escape_markup(plot.script) << "\">" << runtime::escape_markup(plot.script)
      << "</a>.";
    if (!plot.gnuplot_stderr.empty()) {
      h << " <span class=\"warn\">gnuplot: " << runtime::escape_markup(plot.gnuplot_stderr)
        << "</span>";
    }
    h << "</figcaption>\n</figure>\n";
  }
  if (!plots.skipped.empty() || !plots.failed.empty()) {
    h << "<h3>Figures not made</h3>\n<ul>\n";
    for (const SkippedPlot& s : plots.skipped) {
      h << "<li><code>" << runtime::escape_markup(s.png)
        << "</code>: no data: " << runtime::escape_markup(s.reason) << "</li>\n";
    }
    for (const SkippedPlot& s : plots.failed) {
      h << "<li class=\"warn\"><code>" << runtime::escape_markup(s.png)
        << "</code>: FAILED: " << runtime::escape_markup(s.reason) << "</li>\n";
    }
    h << "</ul>\n";
  }

  // 3. Every figure of the summary.
  h << "<h2>All figures of this run</h2>\n<p>Also in <a href=\"summary.json\">summary.json</a>."
       "</p>\n<table>\n<tr><th>key</th><th>value</th><th>meaning</th></tr>\n";
  for (const SummaryField& field : summary_fields()) {
    h << "<tr><td><code>" << field.key << "</code></td><td class=\"num\">"
      << format_figure(summary.*field.member) << "</td><td>"
      << runtime::escape_markup(field.description) << "</td></tr>\n";
  }
  h << "</table>\n<h2>Data</h2>\n<p><a href=\"frames.csv\">frames.csv</a>, <a "
       "href=\"meta.csv\">meta.csv</a>; the format is described in docs/report.md. "
       "Re-make this page with <code>avs report &lt;this folder&gt;</code>.</p>\n"
    << "</body>\n</html>\n";
  return h.str();
}

Report make_report(const fs::path& dir_given, const ReportOptions& options) {
  // Absolute: gnuplot runs inside the run folder, so a relative path would not resolve there.
  const fs::path dir = fs::absolute(dir_given);
  Report report;
  const RunData run = load_run(dir);
  report.info = run.info;
  report.warnings = run.warnings;
  report.summary = compute_summary(run);
  report.summary_json = dir / kSummaryFile;
  write_file(report.summary_json, to_json(report.summary, run.info.scenario) + "\n");
  report.plots = make_plots(run, options.plots);
  report.index_html = dir / kIndexFile;
  write_file(report.index_html,
             render_index_html(run.info, report.summary, report.plots, run.warnings));
  return report;
}

int report_main(const fs::path& dir, std::ostream& out, std::ostream& err,
                const ReportOptions& options) {
  try {
    const Report report = make_report(dir, options);
    out << "avs report: " << report.info.scenario << " (" << report.info.object << "), "
        << format_figure(report.summary.frames) << " depth updates\n\n"
        << format_comparison_table(report.info.scenario, report.summary)
        << format_run_clocks(report.summary) << "\n";
    if (!report.info.notes.empty()) out << "Notes: " << report.info.notes << "\n";
    out << kPaperNote << "\n\n";
    for (const std::string& warning : report.warnings) err << "warning: " << warning << "\n";
    for (const SkippedPlot& s : report.plots.skipped) {
      out << "not made: " << s.png << " (" << s.reason << ")\n";
    }
    for (const Plot& p : report.plots.made) {
      if (!p.gnuplot_stderr.empty())
        err << "gnuplot warning for " << p.png << ": " << p.gnuplot_stderr << "\n";
    }
    for (const SkippedPlot& s : report.plots.failed)
      err << "FAILED: " << s.png << ": " << s.reason << "\n";
    out << "report: " << report.index_html.string() << "\n";
    return report.plots.failed.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    err << "avs report: " << e.what() << "\n";
    return 1;
  }
}

int report_main(const fs::path& dir) {
  return report_main(dir, std::cout, std::cerr);
}

std::string experiments_json(const std::vector<std::pair<std::string, Summary>>& runs) {
  std::string out = "{";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    out += (i == 0 ? "" : ", ") + json_string(runs[i].first) + ": " +
           to_json(runs[i].second, runs[i].first);
  }
  return out + "}";
}

}  // namespace avs::report
