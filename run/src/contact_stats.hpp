// Accumulating ContactStats (run.hpp) from the multipliers, one sample at a time.
#pragma once

#include <appell/run.hpp>

namespace appell::run_detail {

/// One entry per constraint; the normal and tangential rows are found by their
/// kind (RowKind), μ is the scene's (index-aligned contacts).
std::vector<ContactStats> contactStats(const Scene& scene);

/// Marks the normal rows that move nothing at the simulator's state — a
/// contact whose normal the joints already hold (a sleigh on a planar joint:
/// its blade's normal row is zero, redundant by construction) carries no load
/// to judge, so it is not reported as pulling.
void markHeldNormals(std::vector<ContactStats>& stats, const Scene& scene, const Simulator& sim);

/// Adds the sample (t, λ) to every entry; open contacts (`cdata`'s active
/// set) count as open samples. No allocation.
void sample(std::vector<ContactStats>& stats, double t, const VecX& lambda,
            const ConstraintData& cdata);

}  // namespace appell::run_detail
