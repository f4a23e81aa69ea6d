#include "validation/report/csv.hpp"

#include <stdexcept>

#include "validation/report/json_value.hpp"

namespace redmax::validation {

void CsvTable::addRow(const std::vector<double>& values) {
  std::vector<std::string> cells;
  cells.reserve(values.size());
  for (double v : values) cells.push_back(formatNumber(v));
  rows.push_back(std::move(cells));
}

void CsvTable::addRow(const std::string& first, const std::vector<double>& values) {
  std::vector<std::string> cells{first};
  for (double v : values) cells.push_back(formatNumber(v));
  rows.push_back(std::move(cells));
}

std::string quoteCsvField(const std::string& field) {
  if (field.find_first_of(",\"\r\n") == std::string::npos) return field;
  std::string o = "\"";
  for (char c : field) {
    if (c == '"') o += '"';
    o += c;
  }
  return o + "\"";
}

std::string formatCsv(const CsvTable& table) {
  std::string out;
  auto line = [&](const std::vector<std::string>& cells) {
    for (size_t i = 0; i < cells.size(); ++i) {
      if (i) out += ',';
      out += quoteCsvField(cells[i]);
    }
    out += '\n';
  };
  line(table.header);
  for (size_t r = 0; r < table.rows.size(); ++r) {
    if (table.rows[r].size() != table.header.size()) {
      throw std::invalid_argument("CSV row " + std::to_string(r + 1) + " has " + std::to_string(table.rows[r].size()) +
                                  " cells but the header has " + std::to_string(table.header.size()));
    }
    line(table.rows[r]);
  }
  return out;
}

CsvTable parseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> rec;
  std::string field;
  bool quoted = false, any = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
      continue;
    }
    if (c == '"') {
      quoted = true;
      any = true;
    } else if (c == ',') {
      rec.push_back(std::move(field));
      field.clear();
    } else if (c == '\n' || c == '\r') {
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      rec.push_back(std::move(field));
      field.clear();
      records.push_back(std::move(rec));
      rec.clear();
      any = false;
      continue;
    } else {
      field += c;
    }
    any = true;
  }
  if (quoted) throw std::invalid_argument("CSV: unterminated quoted field");
  if (any || !rec.empty()) {
    rec.push_back(std::move(field));
    records.push_back(std::move(rec));
  }
  CsvTable t;
  if (records.empty()) return t;
  t.header = std::move(records.front());
  for (size_t r = 1; r < records.size(); ++r) {
    if (records[r].size() != t.header.size()) {
      throw std::invalid_argument("CSV record " + std::to_string(r + 1) + " has " + std::to_string(records[r].size()) +
                                  " fields but the header has " + std::to_string(t.header.size()));
    }
    t.rows.push_back(std::move(records[r]));
  }
  return t;
}

}  // namespace redmax::validation
