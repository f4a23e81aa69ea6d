#pragma once
// CSV tables for reports (RFC 4180: comma-separated, fields quoted when they hold a comma, a quote
// or a line break; "\n" line ends). Numbers are written in the shortest form that reads back to
// the same double; non-finite values as nan / inf / -inf (what spreadsheets and numpy accept).
#include <string>
#include <vector>

namespace redmax::validation {

/// A table of text cells with a header row.
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  ///< each row has header.size() cells

  /// append a row of numbers (formatNumber)
  void addRow(const std::vector<double>& values);
  /// append a row whose first cell is text and the rest numbers
  void addRow(const std::string& first, const std::vector<double>& values);
  /// append a row of text cells
  void addRow(std::vector<std::string> cells) { rows.push_back(std::move(cells)); }
};

/// One CSV field, quoted if needed.
std::string quoteCsvField(const std::string& field);
/// The whole table as CSV text. Throws std::invalid_argument if a row's length differs from the
/// header's.
std::string formatCsv(const CsvTable& table);
/// Parse CSV text (as formatCsv writes it: the first record is the header). Throws
/// std::invalid_argument on an unterminated quote or ragged rows.
CsvTable parseCsv(const std::string& text);

}  // namespace redmax::validation
