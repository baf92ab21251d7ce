// Is a failed fixed-step run's root cause the step itself? An explicit
// method with step h is stable on a linear mode ẋ = λx only where its
// stability function keeps |R(λh)| ≤ 1 — for RK4
//     R(z) = 1 + z + z²/2 + z³/6 + z⁴/24
// (Hairer & Wanner, "Solving Ordinary Differential Equations II", 1996,
// §IV.2). A motion whose modes speed up (a sleigh sliding ever faster down
// an incline: its yaw mode's rate grows with the speed) crosses that limit
// in mid-run, and what fails first is a symptom — a contact that switches at
// every step, an energy error, a residual. Here the linearized constrained
// flow at the last state (linearization.hpp, the contacts that are closed)
// is checked against RK4's region: a mode that does not grow physically
// (Re λ ≤ 0) but has |R(λh)| > 1 is the cause, named with the largest step
// that would keep every such mode stable.
#pragma once

#include <appell/run.hpp>

#include <string>

namespace appell::run_detail {

/// "; the root cause: …" when the run's fixed step is outside RK4's stability
/// region for the motion at sim's state; "" otherwise (adaptive or
/// symplectic-Euler runs, models of more than 200 velocities, a
/// linearization that fails, or every mode inside the region).
std::string stepStabilityCause(const Scene& scene, const Simulator& sim, const RunOptions& options);

}  // namespace appell::run_detail
