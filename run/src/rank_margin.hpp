// Rows independent only by a margin (RunSummary::near_dependency): the
// freedom that CAD rounding takes away, watched at a sampled cadence.
//
// The tree solver decides the rank of the closed rows with SolverOptions'
// thresholds and says nothing about rows it keeps: two lateral rows of a
// differential drive whose wheels a CAD export turned by 7.96e-4 rad
// (rpy="-1.57") are independent by that much, and the robot cannot turn.
// Every sampled state (t = 0, each step with a contact event, and every
// duration/256 of simulated time) this watch forms the closed rows densely,
// in the mass metric, and finds their smallest singular value above the
// rank threshold; below RunOptions::near_dependency_level it is recorded
// with the rows and the motion it locks (run.hpp, NearDependency). O(nv³)
// per check, never inside a step: the step loop stays O(n).
#pragma once

#include <appell/data.hpp>
#include <appell/run.hpp>
#include <appell/scene.hpp>
#include <appell/simulator.hpp>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace appell::run_detail {

class RankMarginWatch {
 public:
  RankMarginWatch(const Scene& scene, const RunOptions& options);
  /// Off with RunOptions::near_dependency_level 0, without rows, and for
  /// models beyond 300 velocities or 1200 rows (the dense check would
  /// outweigh the run).
  bool active() const { return level_ > 0; }
  /// Checks the simulator's state if a check is due (`event`: the step had a
  /// contact event, so the set of closed rows changed), updating `out`.
  void sample(const Simulator& sim, bool event, NearDependency& out);

 private:
  void check(const Simulator& sim, NearDependency& out);
  /// Names of the rows and coordinates a near-dependency combines.
  void describe(const Simulator& sim, int k, NearDependency& out);

  const Scene& scene_;
  double level_ = 0, threshold_, rel_tol_, every_, next_ = 0;
  double last_ = -std::numeric_limits<double>::infinity();  ///< time of the last check
  std::vector<std::string> coordinates_;
  std::unique_ptr<Data> data_;
  MatX A_, J_, B_;
  VecX abias_, scale_;
  Eigen::LLT<MatX> llt_;
  std::unique_ptr<Eigen::JacobiSVD<MatX>> svd_;
};

}  // namespace appell::run_detail
