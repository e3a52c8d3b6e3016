#include "avs/report/table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace avs::report {
namespace {

bool looks_numeric(const std::string& cell) {
  if (cell.empty() || cell == "-") return !cell.empty();
  return std::all_of(cell.begin(), cell.end(), [](char c) {
    return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e';
  });
}

/// Display width of UTF-8 text (counts code points, not bytes).
std::size_t display_width(const std::string& text) {
  return static_cast<std::size_t>(std::count_if(text.begin(), text.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  }));
}

}  // namespace

void TextTable::add_row(std::vector<std::string> cells) {
  if (cells.size() != headers_.size()) {
    throw ReportError("TextTable: row of " + std::to_string(cells.size()) + " cells, header has " +
                      std::to_string(headers_.size()));
  }
  rows_.push_back(std::move(cells));
}

std::string TextTable::render() const {
  // A column is right-aligned when every cell in it is a number (or "-").
  std::vector<std::size_t> widths(headers_.size());
  std::vector<bool> right(headers_.size(), !rows_.empty());
  for (std::size_t c = 0; c < headers_.size(); ++c) {
    widths[c] = display_width(headers_[c]);
    for (const auto& row : rows_) {
      widths[c] = std::max(widths[c], display_width(row[c]));
      if (!looks_numeric(row[c])) right[c] = false;
    }
  }
  std::string out;
  const auto emit = [&](const std::vector<std::string>& cells) {
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::size_t pad = widths[c] - display_width(cells[c]);
      if (c > 0) out += "  ";
      if (right[c]) out.append(pad, ' ');
      out += cells[c];
      if (!right[c] && c + 1 < cells.size()) out.append(pad, ' ');
    }
    out += '\n';
  };
  emit(headers_);
  std::size_t total = 0;
  for (std::size_t w : widths) total += w;
  out.append(total + 2 * (widths.size() - 1), '-');
  out += '\n';
  for (const auto& row : rows_) emit(row);
  return out;
}

std::string format_figure(double value) {
  if (!std::isfinite(value)) return "-";
  char buffer[64];
  if (value == std::round(value) && std::abs(value) < 1e15) {
    std::snprintf(buffer, sizeof(buffer), "%.0f", value);
  } else if (std::abs(value) >= 1000.0) {
    std::snprintf(buffer, sizeof(buffer), "%.0f", value);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  }
  return buffer;
}

std::string markdown_cell(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

const std::vector<std::string>& comparison_headers() {
  static const std::vector<std::string> headers{"figure", "statistic", "clock",   "paper",
                                                "ours",   "unit",      "verdict", "section"};
  return headers;
}

namespace {

std::vector<std::string> comparison_cells(const ComparisonRow& row) {
  return {row.label,
          row.statistic,
          row.clock,
          row.paper,
          format_figure(row.ours),
          row.unit,
          row.verdict.empty() ? "-" : row.verdict,
          row.section};
}

}  // namespace

std::string format_comparison_table(const std::string& scenario, const Summary& summary) {
  TextTable table(comparison_headers());
  for (const ComparisonRow& row : comparison_rows(scenario, summary)) {
    table.add_row(comparison_cells(row));
  }
  return table.render();
}

std::string format_comparison_markdown(const std::string& scenario, const Summary& summary) {
  std::string out = "|";
  std::string rule = "|";
  for (const std::string& header : comparison_headers()) {
    out += " " + header + " |";
    rule += header == "paper" || header == "ours" ? "---:|" : "---|";
  }
  out += "\n" + rule + "\n";
  for (const ComparisonRow& row : comparison_rows(scenario, summary)) {
    out += "|";
    for (const std::string& text : comparison_cells(row)) out += " " + markdown_cell(text) + " |";
    out += "\n";
  }
  return out;
}

std::string format_run_clocks(const Summary& summary) {
  std::string out = "Run: " + format_figure(summary.duration_s) + " s of simulated time";
  if (std::isfinite(summary.wall_duration_s)) {
    out += " in " + format_figure(summary.wall_duration_s) + " s of wall-clock time";
  }
  if (std::isfinite(summary.real_time_factor)) {
    out += " (real-time factor " + format_figure(summary.real_time_factor) + ")";
  } else {
    out += " (real-time factor unknown: no wall_s in the run folder, or a single row)";
  }
  return out +
         ". Clock 'sim': per second of simulated time; 'wall': measured on this machine's "
         "wall clock (on its CPU; the paper's depth computation ran on a GPU); '-': against "
         "ground truth. A verdict compares ours with the paper's limit (rates within " +
         format_figure(kRateTolerance * 100.0) + " % of the paper's).";
}

}  // namespace avs::report
