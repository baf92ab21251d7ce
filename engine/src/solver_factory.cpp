#include <appell/appell_maggi.hpp>
#include <appell/constrained_dynamics.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

namespace appell {

std::unique_ptr<ConstrainedSolver> makeSolver(Formulation f, const Model& model,
                                              const ConstraintList& constraints,
                                              const SolverOptions& options) {
  switch (f) {
    case Formulation::Tree: return makeTreeSolver(model, constraints, options);
    case Formulation::Multipliers: return std::make_unique<KktSolver>(model, constraints, options);
    case Formulation::Appell: return std::make_unique<AppellSolver>(model, constraints, options);
  }
  throw std::invalid_argument("unknown formulation");
}

}  // namespace appell
