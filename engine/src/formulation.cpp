#include <appell/constrained_dynamics.hpp>

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

}  // namespace appell
