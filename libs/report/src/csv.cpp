#include "csv.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "avs/report/run_data.hpp"

namespace avs::report::csv {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string::npos) {
      fields.push_back(line.substr(start));
      return fields;
    }
    fields.push_back(line.substr(start, comma - start));
    start = comma + 1;
  }
}

std::string format_number(double value) {
  if (std::isnan(value)) return "";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

Table Table::read(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ReportError(file.string() + ": cannot open for reading");
  std::ostringstream contents;
  contents << in.rdbuf();
  const std::string text = contents.str();
  Table table;
  table.file_ = file;
  std::size_t start = 0;
  int line_number = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    const bool complete = end != std::string::npos;
    if (!complete) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;  // blank lines (e.g. a trailing one) carry no row
    const std::string where = file.string() + ":" + std::to_string(line_number);
    if (line.find('"') != std::string::npos) {
      throw ReportError(where + ": quoted fields are not supported");
    }
    std::vector<std::string> fields = split(line);
    if (table.header_.empty()) {
      table.header_ = std::move(fields);
      continue;
    }
    if (!complete && fields.size() < table.header_.size()) {
      table.warnings_.push_back(where + ": last line is cut short (" +
                                std::to_string(fields.size()) + " of " +
                                std::to_string(table.header_.size()) +
                                " fields, no newline): ignored; the writer stopped mid-row");
      continue;
    }
    if (fields.size() != table.header_.size()) {
      throw ReportError(where + ": expected " + std::to_string(table.header_.size()) +
                        " fields (as in the header), got " + std::to_string(fields.size()));
    }
    table.rows_.push_back(std::move(fields));
    table.lines_.push_back(line_number);
  }
  if (table.header_.empty()) throw ReportError(file.string() + ":1: empty file, expected a header");
  return table;
}

std::optional<std::size_t> Table::find_column(const std::string& name) const {
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == name) return i;
  }
  return std::nullopt;
}

std::size_t Table::column(const std::string& name) const {
  if (auto index = find_column(name)) return *index;
  throw ReportError(file_.string() + ":1: missing column '" + name + "'");
}

std::string Table::where(std::size_t row) const {
  return file_.string() + ":" + std::to_string(lines_[row]);
}

std::string Table::where(std::size_t row, std::size_t col) const {
  return where(row) + ": column '" + header_[col] + "'";
}

std::optional<double> Table::optional_number(std::size_t row, std::size_t col) const {
  const std::string& field = rows_[row][col];
  if (field.empty()) return std::nullopt;
  double value = 0.0;
  const auto result = std::from_chars(field.data(), field.data() + field.size(), value);
  if (result.ec != std::errc() || result.ptr != field.data() + field.size()) {
    throw ReportError(where(row, col) + ": cannot parse '" + field + "' as a number");
  }
  if (!std::isfinite(value)) {
    throw ReportError(where(row, col) + ": '" + field + "' is not finite (leave it empty)");
  }
  return value;
}

double Table::number(std::size_t row, std::size_t col) const {
  if (auto value = optional_number(row, col)) return *value;
  throw ReportError(where(row, col) + ": empty, a number is required");
}

long Table::integer(std::size_t row, std::size_t col) const {
  const std::string& field = rows_[row][col];
  long value = 0;
  const auto result = std::from_chars(field.data(), field.data() + field.size(), value);
  if (field.empty() || result.ec != std::errc() || result.ptr != field.data() + field.size()) {
    throw ReportError(where(row, col) + ": cannot parse '" + field + "' as an integer");
  }
  return value;
}

bool Table::flag(std::size_t row, std::size_t col) const {
  const std::string& field = rows_[row][col];
  if (field == "0") return false;
  if (field == "1") return true;
  throw ReportError(where(row, col) + ": expected 0 or 1, got '" + field + "'");
}

}  // namespace avs::report::csv
