#include <appell/integrators.hpp>

#include "integrators/integrators_impl.hpp"

#include <stdexcept>

namespace appell {

const char* toString(IntegratorType type) {
  switch (type) {
    case IntegratorType::SymplecticEuler: return "euler";
    case IntegratorType::RK4: return "rk4";
    case IntegratorType::DormandPrince54: return "dopri5";
  }
  return "?";
}

IntegratorType integratorFromString(const std::string& name) {
  if (name == "euler" || name == "symplectic-euler" || name == "semi-implicit-euler")
    return IntegratorType::SymplecticEuler;
  if (name == "rk4") return IntegratorType::RK4;
  if (name == "dopri5" || name == "dormand-prince" || name == "rk45")
    return IntegratorType::DormandPrince54;
  throw std::invalid_argument("unknown integrator '" + name +
                              "' (expected one of: euler, rk4, dopri5)");
}

std::unique_ptr<Integrator> makeIntegrator(IntegratorType type, const Model& model,
                                           const IntegratorOptions& options) {
  switch (type) {
    case IntegratorType::SymplecticEuler: return std::make_unique<detail::SymplecticEuler>(model);
    case IntegratorType::RK4: return std::make_unique<detail::RungeKutta4>(model);
    case IntegratorType::DormandPrince54:
      return std::make_unique<detail::DormandPrince54>(model, options);
  }
  throw std::invalid_argument("unknown integrator type");
}

}  // namespace appell
