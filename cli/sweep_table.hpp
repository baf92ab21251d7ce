// A sweep's table: one row per case, columns named once for all rows, written
// as CSV (RFC 4180: a header line, a text cell quoted when it holds a comma,
// a quote or a line break) or as JSON (an object per row, the same keys; a
// missing cell and a non-finite number are null). Numbers are written as the
// shortest text that reads back as the same double, so a row read back
// equals the computation bit for bit.
#pragma once

#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace appell::cli {

/// One cell: empty, a number, a count or a text.
struct Cell {
  enum class Kind { Empty, Number, Count, Text } kind = Kind::Empty;
  double number = 0;
  long count = 0;
  std::string text;
  static Cell of(double x) { return {Kind::Number, x, 0, {}}; }
  static Cell ofCount(long n) { return {Kind::Count, 0, n, {}}; }
  static Cell ofText(std::string s) { return {Kind::Text, 0, 0, std::move(s)}; }
};

/// A row: cells by column name (a column the row lacks is empty).
using SweepRow = std::map<std::string, Cell>;

struct SweepTable {
  std::vector<std::string> columns;
  std::vector<SweepRow> rows;

  void writeCsv(std::ostream& out) const;
  /// {"<key>": <value>, …, "cases": [rows]} with `head` the leading pairs
  /// (already JSON values: "\"run\"", "42").
  void writeJson(std::ostream& out, const std::vector<std::pair<std::string, std::string>>& head) const;
};

/// A JSON string literal of `s` (quotes, backslashes and control characters escaped).
std::string jsonString(const std::string& s);

}  // namespace appell::cli
