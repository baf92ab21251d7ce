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
//                            planar    .vx .vy .omega   (link frame, along t₁ t₂)
//                            floating  .wx .wy .wz .vx .vy .vz   (link frame; v of
//                                      the link origin, not the centre of mass)
//                            ball      .wx .wy .wz
//   energy, residual
//   per constraint c:  point:<c>.x .y .z,  normal:<c>.x .y .z,
//                      lambda:<c>.<row label>   (one per row, e.g. tangent1)
//                      unilateral constraints (contacts, limits) also:
//                      closed:<c>   1 closed, 0 open (lifted off, in flight)
//                      event:<c>    the event at this sample's time: 0 none,
//                                   1 touchdown, 2 bounce, 3 lift-off,
//                                   4 slip, 5 stick
//                                   (1 + ContactEventKind, contact_events.hpp)
// A step that ends at an event is always written, so each event is a row.
// Numbers are written in the shortest form that reads back to the same double.
// Fields holding a comma or a quote are quoted (RFC 4180).
#pragma once

#include <appell/constraint_set.hpp>
#include <appell/joint_types.hpp>
#include <appell/scene.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace appell {

/// One unilateral constraint in one sample (the closed:/event: columns).
struct ContactState {
  bool closed = true;
  int event = 0;  ///< 0: none; 1 + ContactEventKind
};

/// The column names described above.
std::vector<std::string> trajectoryColumns(const Model& model, const ConstraintList& constraints);

// coordinateNames() and localCoordinateIndex(), the column names' source,
// are the engine's (joint_types.hpp: the joint type table's names).

class TrajectoryWriter {
 public:
  /// Writes the header line at once.
  TrajectoryWriter(std::ostream& out, const Scene& scene);
  TrajectoryWriter(std::ostream& out, const Model& model, const ConstraintList& constraints);

  /// One sample. `frames` has one entry per constraint (ContactFrame from the
  /// evaluated RowBlock), `lambda` one entry per constraint row, constraints
  /// in order. Throws std::invalid_argument on a size mismatch.
  /// `states`: one per constraint (only the unilateral ones are written);
  /// empty: every contact closed, no event.
  void write(double t, const VecX& q, const VecX& v, double energy, double residual,
             const std::vector<ContactFrame>& frames, const VecX& lambda,
             const std::vector<ContactState>& states = {});

  const std::vector<std::string>& columns() const { return columns_; }
  long samples() const { return samples_; }

 private:
  void put(double x);
  std::ostream& out_;
  int nq_, nv_, nconstraints_, nrows_;
  std::vector<int> rows_;  ///< rows per constraint
  std::vector<char> unilateral_;  ///< per constraint: has closed:/event: columns
  std::vector<std::string> columns_;
  std::string line_;
  long samples_ = 0;
};

}  // namespace appell
