#include <appell/constrained_dynamics.hpp>
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include <stdexcept>

namespace appell {

std::span<const NamedValue<Formulation>> formulationTable() {
  static const NamedValue<Formulation> table[] = {
      {Formulation::Tree, "tree", {}, "Gauss' principle on the kinematic tree, O(n + m) (default)"},
      {Formulation::Multipliers, "kkt", {"multipliers"}, "dense Lagrange multipliers (KKT), the reference"},
      {Formulation::Appell, "appell", {"maggi"}, "dense Appell/Maggi equations on the null space"},
  };
  return table;
}

const char* toString(Formulation f) { return entryOf(formulationTable(), f).name; }

Formulation formulationFromString(const std::string& name) {
  return parseName(formulationTable(), name, "formulation");
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
