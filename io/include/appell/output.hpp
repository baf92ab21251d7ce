// Trajectories out: one CSV row per sample, one named column per number.
//
// Columns, in order:
//   time
//   q:<joint>[.<coord>]    nq columns; coordinates per joint type:
//                            revolute, continuous, prismatic   (none: q:<joint>)
//                            planar    .x .y .theta
//                            floating  .x .y .z .qx .qy .qz .qw
//                            ball      .qx .qy .qz .qw
//   v:<joint>[.<coord>]    nv columns:
//                            planar    .vx .vy .omega   (body frame)
//                            floating  .wx .wy .wz .vx .vy .vz   (body frame)
//                            ball      .wx .wy .wz
//   energy, residual
//   per constraint c:  point:<c>.x .y .z,  normal:<c>.x .y .z,
//                      lambda:<c>.<row label>   (one per row, e.g. tangent1)
// Numbers are written in the shortest form that reads back to the same double.
// Fields holding a comma or a quote are quoted (RFC 4180).
#pragma once

#include <appell/constraint_set.hpp>
#include <appell/scene.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace appell {

/// The column names described above.
std::vector<std::string> trajectoryColumns(const Model& model, const ConstraintList& constraints);

class TrajectoryWriter {
 public:
  /// Writes the header line at once.
  TrajectoryWriter(std::ostream& out, const Scene& scene);
  TrajectoryWriter(std::ostream& out, const Model& model, const ConstraintList& constraints);

  /// One sample. `frames` has one entry per constraint (ContactFrame from the
  /// evaluated RowBlock), `lambda` one entry per constraint row, constraints
  /// in order. Throws std::invalid_argument on a size mismatch.
  void write(double t, const VecX& q, const VecX& v, double energy, double residual,
             const std::vector<ContactFrame>& frames, const VecX& lambda);

  const std::vector<std::string>& columns() const { return columns_; }
  long samples() const { return samples_; }

 private:
  void put(double x);
  std::ostream& out_;
  int nq_, nv_, nconstraints_, nrows_;
  std::vector<int> rows_;  ///< rows per constraint
  std::vector<std::string> columns_;
  std::string line_;
  long samples_ = 0;
};

}  // namespace appell
