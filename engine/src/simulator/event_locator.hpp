// EventLocator: the first zero of one event function φ(τ) along a step,
// written once for every kind of event (a gap, a normal force, a friction
// cone, a slip, a change of terrain piece).
//
// The caller supplies two callbacks over its own state:
//   stateAt(τ) → the state at τ after the step's start (on the integrator's
//                dense output, or a proper step shortened to τ), returning
//                the τ actually reached (an adaptive method may take less
//                than asked) or NaN when that step failed;
//   phi()      → φ at that state (NaN when a solve failed).
// With φ(0) > 0 ≥ φ(hi), the root is bracketed and narrowed by the Illinois
// method (modified regula falsi: Dowell & Jarratt 1971, "A modified regula
// falsi method for computing the root of an equation", BIT 11), or by
// bisection for a step function (a change of piece), until the bracket is
// below time_tol or max_iterations are spent. The result is the bracket's
// right end: the earliest τ known to be at or past the event. A gap or slip
// that is zero at the start but grows just after (a contact that opened or
// started sliding there) is bracketed from a point shortly after the start.
#pragma once

#include <cmath>

namespace appell::detail {

struct EventLocator {
  int max_iterations = 50;
  double time_tol = 1e-12;

  enum class Status {
    Ok,
    StartStepFailed,  ///< the state at the bracket's ends could not be reached
    EndsNotFinite,    ///< φ is not finite at the bracket's ends
    StepFailed,       ///< a shortened step inside the bracket failed
    NotFinite,        ///< φ is not finite inside the bracket
  };

  /// Sets `tau` to the located event's time after the step's start (0 when
  /// φ(0) ≤ 0 even after the separating-start bracketing). `separating_start`:
  /// φ(0) ≈ 0 may grow just after (gaps, slips); `step_function`: bisect.
  template <class StateAt, class Phi>
  Status locate(StateAt&& stateAt, Phi&& phi, double hi, bool separating_start,
                bool step_function, double& tau) const {
    double a = 0, b = hi;
    if (std::isnan(stateAt(a))) return Status::StartStepFailed;
    double fa = phi();
    b = stateAt(b);
    if (std::isnan(b)) return Status::StartStepFailed;
    double fb = phi();
    if (!std::isfinite(fa) || !std::isfinite(fb)) return Status::EndsNotFinite;
    if (fa <= 0 && separating_start) {
      for (double s = 0.5; s > 1e-9 && fa <= 0; s *= 0.25) {
        const double reached = stateAt(s * b);
        if (std::isnan(reached)) return Status::StepFailed;
        const double f = phi();
        if (f > 0) {
          a = reached;
          fa = f;
        }
      }
    }
    if (fa <= 0) {
      tau = 0;  // already at (or past) the event at the start: decide there
      return Status::Ok;
    }
    return narrow(stateAt, phi, step_function, a, fa, b, fb, tau);
  }

 private:
  /// Illinois (or bisection) on [a, b] with φ(a) > 0 ≥ φ(b).
  template <class StateAt, class Phi>
  Status narrow(StateAt& stateAt, Phi& phi, bool step_function, double a, double fa, double b,
                double fb, double& tau) const {
    int side = 0;
    for (int it = 0; it < max_iterations && b - a > time_tol; ++it) {
      double c = step_function ? 0.5 * (a + b) : (a * fb - b * fa) / (fb - fa);
      if (!(c > a && c < b)) c = 0.5 * (a + b);
      c = stateAt(c);
      if (std::isnan(c)) return Status::StepFailed;
      const double fc = phi();
      if (!std::isfinite(fc)) return Status::NotFinite;
      if (fc > 0) {
        a = c;
        fa = fc;
        if (side == 1) fb *= 0.5;
        side = 1;
      } else {
        b = c;
        fb = fc;
        if (side == -1) fa *= 0.5;
        side = -1;
      }
      if (fc == 0) break;
    }
    tau = b;
    return Status::Ok;
  }
};

}  // namespace appell::detail
