// Trajectories in: a CSV that TrajectoryWriter (output.hpp) wrote, read back
// as named columns of doubles, so `appell view` and `appell plot` see exactly
// the numbers the run wrote (they are written in the shortest form that reads
// back to the same double, and read here with std::from_chars).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace appell {

struct TrajectoryTable {
  std::string source;                       ///< the file, for messages
  std::vector<std::string> columns;         ///< header names (output.hpp lists them)
  std::vector<std::vector<double>> rows;    ///< one per sample, columns.size() numbers each

  /// Index of the named column, −1 if absent.
  int find(const std::string& name) const;
  /// Index of the named column; throws std::runtime_error naming file and column if absent.
  int require(const std::string& name) const;
  /// One column over all samples.
  std::vector<double> column(int index) const;
};

/// Larger trajectory files are refused (2 GiB: 10⁷ rows of 25 columns).
constexpr std::uintmax_t kMaxTrajectoryBytes = std::uintmax_t{2} << 30;

/// Reads a trajectory CSV (RFC 4180 quoting in the header, line breaks inside
/// quoted names included). Throws std::runtime_error naming file, line and
/// reason on a malformed file, and for anything but a regular file of at most
/// kMaxTrajectoryBytes.
TrajectoryTable readTrajectory(const std::string& path);

}  // namespace appell
