// Which mass distributions the dynamics can run, and the opt-in repairs of
// inertias as published (ModelBuilder::build's second half; model.hpp).
#pragma once

#include <appell/model.hpp>

#include <string>
#include <vector>

namespace appell::detail {

/// model.spatial_inertia[i] and its Cholesky factor from model.inertias[i].
void cacheSpatialInertia(Model& model, int i);

/// Applies `repairs` to every rigid group (model.hpp, InertiaRepairs): the
/// correction goes into the moving body's own inertia (and its cached spatial
/// inertia and factor). notes[body] (one per body) says what changed.
void repairInertias(Model& model, const InertiaRepairs& repairs, std::vector<std::string>& notes);

/// Judges every rigid group and every joint whose group is singular; throws
/// ModelError for what the dynamics cannot run; a group loaded with a defect
/// has it said in notes[body] (after its repair, when it had one).
void checkInertias(const Model& model, std::vector<std::string>& notes);

}  // namespace appell::detail
