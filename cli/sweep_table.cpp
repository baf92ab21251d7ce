// Writing a sweep's table as CSV or JSON (sweep_table.hpp).
#include "sweep_table.hpp"

#include "sweep_engine.hpp"

#include <cmath>
#include <cstdio>

namespace appell::cli {

namespace {

std::string csvText(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string csvCell(const Cell& c) {
  switch (c.kind) {
    case Cell::Kind::Number: return exact(c.number);
    case Cell::Kind::Count: return std::to_string(c.count);
    case Cell::Kind::Text: return csvText(c.text);
    case Cell::Kind::Empty: break;
  }
  return "";
}

std::string jsonCell(const Cell& c) {
  switch (c.kind) {
    case Cell::Kind::Number: return std::isfinite(c.number) ? exact(c.number) : "null";
    case Cell::Kind::Count: return std::to_string(c.count);
    case Cell::Kind::Text: return jsonString(c.text);
    case Cell::Kind::Empty: break;
  }
  return "null";
}

}  // namespace

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

void SweepTable::writeCsv(std::ostream& out) const {
  for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << csvText(columns[i]);
  out << "\n";
  for (const SweepRow& row : rows) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const auto it = row.find(columns[i]);
      out << (i ? "," : "") << (it == row.end() ? std::string() : csvCell(it->second));
    }
    out << "\n";
  }
}

void SweepTable::writeJson(std::ostream& out, const std::vector<std::pair<std::string, std::string>>& head) const {
  out << "{";
  for (const auto& [key, value] : head) out << jsonString(key) << ": " << value << ", ";
  out << "\"cases\": [";
  for (std::size_t k = 0; k < rows.size(); ++k) {
    out << (k ? ",\n  {" : "\n  {");
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const auto it = rows[k].find(columns[i]);
      out << (i ? ", " : "") << jsonString(columns[i]) << ": " << (it == rows[k].end() ? "null" : jsonCell(it->second));
    }
    out << "}";
  }
  out << "\n]}\n";
}

}  // namespace appell::cli
