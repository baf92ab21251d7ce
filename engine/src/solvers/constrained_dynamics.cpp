#include <appell/constrained_dynamics.hpp>
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include <stdexcept>

namespace appell {

const char* toString(Formulation f) {
  switch (f) {
    case Formulation::Tree: return "tree";
    case Formulation::Multipliers: return "kkt";
    case Formulation::Appell: return "appell";
  }
  return "?";
}

Formulation formulationFromString(const std::string& name) {
  if (name == "tree") return Formulation::Tree;
  if (name == "kkt" || name == "multipliers") return Formulation::Multipliers;
  if (name == "appell" || name == "maggi") return Formulation::Appell;
  throw std::invalid_argument("unknown formulation '" + name +
                              "' (expected one of: tree, kkt, multipliers, appell, maggi)");
}


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
