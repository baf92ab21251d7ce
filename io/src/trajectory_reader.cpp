// Reading back a trajectory CSV (trajectory_reader.hpp), bounded: only a
// regular file of at most kMaxTrajectoryBytes is read (`/dev/zero` once grew
// the table at 250 MB/s until memory ran out, and a FIFO blocked for ever),
// and a header whose quoted names hold line breaks is one record.
#include <appell/trajectory_reader.hpp>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace appell {

namespace {

// Splits one CSV line into fields; "…" quotes a field, "" inside it is a quote.
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') fields.back() += '"', ++i;
      else if (c == '"') quoted = false;
      else fields.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

// One CSV record: lines joined while a quoted field is still open (an
// even number of quotes closes every field; "" inside one is two).
bool readRecord(std::istream& in, std::string& record) {
  if (!std::getline(in, record)) return false;
  std::string more;
  while (std::count(record.begin(), record.end(), '"') % 2 == 1 && std::getline(in, more)) record += "\n" + more;
  return true;
}

void checkReadable(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw std::runtime_error(path + ": no such trajectory file");
  if (!std::filesystem::is_regular_file(status))
    throw std::runtime_error(path + ": not a regular file (a directory, device or pipe is not a trajectory)");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxTrajectoryBytes)
    throw std::runtime_error(path + ": " + std::to_string(size) + " bytes, larger than the " +
                             std::to_string(kMaxTrajectoryBytes >> 20) +
                             " MiB a trajectory may have (write fewer rows: appell run --every N)");
}

}  // namespace

int TrajectoryTable::find(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return static_cast<int>(i);
  return -1;
}

int TrajectoryTable::require(const std::string& name) const {
  const int i = find(name);
  if (i < 0) throw std::runtime_error(source + ": no column '" + name + "'");
  return i;
}

std::vector<double> TrajectoryTable::column(int index) const {
  std::vector<double> out;
  out.reserve(rows.size());
  for (const auto& r : rows) out.push_back(r.at(index));
  return out;
}

TrajectoryTable readTrajectory(const std::string& path) {
  checkReadable(path);
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the trajectory file");
  TrajectoryTable table;
  table.source = path;
  std::string line;
  if (!readRecord(in, line)) throw std::runtime_error(path + ": empty file (no header line)");
  table.columns = splitCsv(line);
  if (table.columns.empty() || table.columns[0] != "time")
    throw std::runtime_error(path + ":1: the header does not start with 'time': not an appell trajectory");
  const long header_lines = 1 + std::count(line.begin(), line.end(), '\n');
  std::uintmax_t bytes = line.size();
  for (long lineno = header_lines + 1; std::getline(in, line); ++lineno) {
    // The file may still be growing (a run writing it): the bound holds for
    // what is read, not only for the size seen at the start.
    bytes += line.size() + 1;
    if (bytes > kMaxTrajectoryBytes)
      throw std::runtime_error(path + ": more than " + std::to_string(kMaxTrajectoryBytes >> 20) +
                               " MiB read: larger than a trajectory may be");
    if (line.empty() || line == "\r") continue;
    std::vector<double> row;
    row.reserve(table.columns.size());
    const char* p = line.data();
    const char* end = p + line.size();
    while (true) {
      double x;
      const auto r = std::from_chars(p, end, x);
      if (r.ec != std::errc())
        throw std::runtime_error(path + ":" + std::to_string(lineno) + ": field " +
                                 std::to_string(row.size() + 1) + " is not a number");
      row.push_back(x);
      p = r.ptr;
      if (p < end && *p == '\r') ++p;
      if (p == end) break;
      if (*p != ',')
        throw std::runtime_error(path + ":" + std::to_string(lineno) + ": field " +
                                 std::to_string(row.size()) + " is not a number");
      ++p;
    }
    if (row.size() != table.columns.size())
      throw std::runtime_error(path + ":" + std::to_string(lineno) + ": " +
                               std::to_string(row.size()) + " fields, the header has " +
                               std::to_string(table.columns.size()));
    table.rows.push_back(std::move(row));
  }
  if (table.rows.empty()) throw std::runtime_error(path + ": no samples after the header");
  return table;
}

}  // namespace appell
