// What the scene-level tests share: the message a scene text is refused
// with, and appell run's options for runs checked against closed forms.
#pragma once

#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <string>

namespace appell::test {

/// Loads the text `xml` named `name`: the SceneError message, or "(loaded)".
inline std::string loadMessage(const std::string& xml, const std::string& name,
                               const LoadOptions& options = {}) {
  try {
    loadSceneFromString(xml, ".", name, options);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(loaded)";
}

/// Dormand–Prince at tol 1e-12 (first step 1e-3): a run whose integration
/// error is negligible against the closed forms it is checked with.
inline RunOptions tightRun(double duration = 1.0, Formulation formulation = Formulation::Tree) {
  RunOptions o;
  o.integrator = IntegratorType::DormandPrince54;
  o.tol = 1e-12;
  o.dt = 1e-3;
  o.duration = duration;
  o.formulation = formulation;
  return o;
}

}  // namespace appell::test
