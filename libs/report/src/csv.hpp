// Minimal CSV reading for the run files: a header row of column names, then rows of
// comma-separated fields without quoting. Every error names file:line and the column.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace avs::report::csv {

class Table {
 public:
  /// Reads the whole file. Throws ReportError for a missing file, an empty file, a quoted
  /// field, or a row whose field count differs from the header's. A last line without its
  /// newline and with too few fields (a writer stopped mid-row) is dropped with a warning.
  [[nodiscard]] static Table read(const std::filesystem::path& file);

  [[nodiscard]] std::size_t rows() const { return rows_.size(); }
  /// 1-based line number in the file of row `row` (the header is line 1).
  [[nodiscard]] int line(std::size_t row) const { return lines_[row]; }
  /// Index of a column; throws ReportError "file:1: missing column 'name'".
  [[nodiscard]] std::size_t column(const std::string& name) const;
  [[nodiscard]] std::optional<std::size_t> find_column(const std::string& name) const;

  [[nodiscard]] const std::string& text(std::size_t row, std::size_t col) const {
    return rows_[row][col];
  }
  /// Parsed fields; throw ReportError "file:line: column 'c': ..." on bad or empty values.
  [[nodiscard]] double number(std::size_t row, std::size_t col) const;
  [[nodiscard]] std::optional<double> optional_number(std::size_t row, std::size_t col) const;
  [[nodiscard]] long integer(std::size_t row, std::size_t col) const;
  [[nodiscard]] bool flag(std::size_t row, std::size_t col) const;  ///< 0 or 1

  /// "file:line: column 'c': " prefix for errors raised by callers.
  [[nodiscard]] std::string where(std::size_t row, std::size_t col) const;
  [[nodiscard]] std::string where(std::size_t row) const;
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  std::filesystem::path file_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<int> lines_;
  std::vector<std::string> warnings_;
};

/// Splits one line at commas (no quoting).
[[nodiscard]] std::vector<std::string> split(const std::string& line);

/// Formats a number for CSV: shortest round-trip form ("0.002", "1e-09"), "" for NaN.
[[nodiscard]] std::string format_number(double value);

}  // namespace avs::report::csv
