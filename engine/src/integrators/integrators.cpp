#include <appell/integrators.hpp>

#include "integrators/integrators_impl.hpp"

#include <stdexcept>

namespace appell {

std::span<const NamedValue<IntegratorType>> integratorTable() {
  static const NamedValue<IntegratorType> table[] = {
      {IntegratorType::SymplecticEuler, "euler", {"symplectic_euler", "semi_implicit_euler"},
       "symplectic (semi-implicit) Euler, fixed step, order 1"},
      {IntegratorType::Leapfrog, "leapfrog", {"verlet", "stormer_verlet", "rattle"},
       "symmetric Störmer–Verlet (leapfrog) + projection (RATTLE-type), fixed step, order 2"},
      {IntegratorType::RK4, "rk4", {}, "classic Runge–Kutta–Munthe-Kaas, fixed step, order 4"},
      {IntegratorType::DormandPrince54, "dopri5", {"dormand_prince", "rk45"},
       "Dormand–Prince 5(4), adaptive step (tol), order 5"},
      {IntegratorType::DormandPrince853, "dop853", {"dopri8", "dormand_prince_853"},
       "Dormand–Prince 8(5,3) (Hairer's DOP853), adaptive step (tol), order 8: for tight tolerances"},
  };
  return table;
}

bool adaptiveIntegrator(IntegratorType type) {
  return type == IntegratorType::DormandPrince54 || type == IntegratorType::DormandPrince853;
}

const char* toString(IntegratorType type) { return entryOf(integratorTable(), type).name; }

IntegratorType integratorFromString(const std::string& name) {
  return parseName(integratorTable(), name, "integrator");
}

std::unique_ptr<Integrator> makeIntegrator(IntegratorType type, const Model& model,
                                           const IntegratorOptions& options) {
  validateOptions(options);
  switch (type) {
    case IntegratorType::SymplecticEuler: return std::make_unique<detail::SymplecticEuler>(model);
    case IntegratorType::Leapfrog: return std::make_unique<detail::Leapfrog>(model, options);
    case IntegratorType::RK4: return std::make_unique<detail::RungeKutta4>(model);
    case IntegratorType::DormandPrince54:
      return std::make_unique<detail::DormandPrince54>(model, options);
    case IntegratorType::DormandPrince853:
      return std::make_unique<detail::DormandPrince853>(model, options);
  }
  throw std::invalid_argument("unknown integrator type");
}

}  // namespace appell
