// Time integrators for  q̇ = G(q) v,  v̇ = f(t, q, v)  on the configuration manifold.
//
// All of them step in local coordinates (configuration.hpp), so quaternions
// move by exact rotations:
//   SymplecticEuler  v⁺ = v + h f(q, v),  q⁺ = retract(q, h v⁺)     order 1
//   Leapfrog         generalised Störmer–Verlet, symmetric          order 2
//                      v½ = v + ½h f(q, v½) + Δ   (implicit: fixed point)
//                      q⁺ = q ⊕ h v½             (configuration.hpp, integrate)
//                      v⁺ = v½ + ½h f(q⁺, v½)
//                    With constraints it is a RATTLE-type scheme: Δ is an
//                    impulse along the rows at q that makes the gaps vanish
//                    at q⁺ and the other rows hold at the midpoint, and the
//                    simulator's projection ends the step on A v + b = 0.
//                    Time-reversible, so energy errors stay bounded on
//                    reversible problems (leapfrog.cpp).
//   RK4              classic 4-stage Runge–Kutta–Munthe-Kaas       order 4
//   DormandPrince54  embedded 5(4) pair, FSAL, error control on (θ, v)
//                    with rtol/atol and the usual PI-free step controller,
//                    and Dormand & Prince's 4th-order continuous extension
//                    as dense output (Hairer, Nørsett, Wanner I, §II.4–6) order 5
//   DormandPrince853 Hairer's DOP853: 12 stages, FSAL, an order-8 error
//                    estimate from the 5th- and 3rd-order embedded pairs,
//                    7th-order dense output from 3 more stages evaluated
//                    on request (Hairer, Nørsett, Wanner I, §II.10)    order 8
// A field may also report scalar rates with each evaluation (the powers of the
// work balance); every method integrates them over the accepted step with its
// own weights — ∫ p dt as if ṗ-free components of the state, so the work
// balance holds to the method's order, not to a trapezoidal rule's.
// Work vectors are allocated at construction; step() does not allocate.
#pragma once

#include <appell/model.hpp>
#include <appell/name_table.hpp>

#include <array>
#include <functional>
#include <memory>
#include <string>

namespace appell {

/// The acceleration field v̇ = f(t, q, v). Returning false means "this state is
/// not admissible" (non-finite, singular); the integrator then rejects the step.
class AccelerationField {
 public:
  /// At most this many rates (rateCount()).
  static constexpr int kMaxRates = 3;
  virtual ~AccelerationField() = default;
  virtual bool operator()(double t, const VecX& q, const VecX& v, VecX& vdot) = 0;
  /// Scalar rates evaluated by the last call of operator() (powers whose
  /// integral over the step the caller wants: StepResult::integrals).
  virtual int rateCount() const { return 0; }
  virtual double rate(int i) const {
    (void)i;
    return 0;
  }
  /// Whether constrainKick() does anything (the field has constraint rows).
  virtual bool constrained() const { return false; }
  /// v ← its M-orthogonal projection onto A(q) v + b(t) = 0 (constrained
  /// fields; the leapfrog evaluates f only at velocities on the constraints,
  /// where redundant rows are consistent). Returns false (remembering why)
  /// when the rows are inconsistent. An unconstrained field leaves v alone.
  virtual bool projectVelocity(double t, const VecX& q, VecX& v) {
    (void)t, (void)q, (void)v;
    return true;
  }
  /// One step toward the leapfrog's discrete constraints on a half-step
  /// velocity w (leapfrog.cpp), by impulses along the rows at (t, q),
  /// w ← w − M(q)⁻¹A(q)ᵀν:
  ///   holonomic rows      g(q ⊕ h w, t + h) = 0              (RATTLE's)
  ///   the other rows      A(q ⊕ ½h w) w + b(t + ½h) = 0     (at the midpoint)
  /// — the M-orthogonal projection at q of those residuals. The rows move
  /// with w by O(h), so one step contracts the residual by O(h) and the
  /// caller iterates. Returns false (remembering why) when the rows are
  /// inconsistent. An unconstrained field leaves w alone.
  virtual bool constrainKick(double t, const VecX& q, double h, VecX& w) {
    (void)t, (void)q, (void)h, (void)w;
    return true;
  }
};

enum class IntegratorType { SymplecticEuler, Leapfrog, RK4, DormandPrince54, DormandPrince853 };
/// Whether the method chooses its steps (tol) rather than taking the given h.
bool adaptiveIntegrator(IntegratorType type);
/// Every integrator with its names ("euler", "rk4", "dopri5" and their aliases):
/// the one list that parsing, error messages and the command-line help read.
std::span<const NamedValue<IntegratorType>> integratorTable();
const char* toString(IntegratorType type);  ///< the canonical name
/// Parses any name or alias of integratorTable(); throws std::invalid_argument
/// listing them all otherwise.
IntegratorType integratorFromString(const std::string& name);

struct IntegratorOptions {
  double rtol = 1e-8;        ///< adaptive only
  double atol = 1e-10;       ///< adaptive only
  double h_min = 1e-14;      ///< adaptive: give up below this step
  double h_max = 0.1;        ///< adaptive: never step further
  double safety = 0.9;
  /// Leapfrog: the implicit half-step's fixed point stops when an iteration
  /// moves (v½, its impulse) by less than implicit_tol · (1 + |v½|∞); it fails the step
  /// (h too large for the velocity-dependent forces) after
  /// implicit_max_iterations. Converging to round-off is what keeps the
  /// method symmetric.
  double implicit_tol = 1e-14;
  int implicit_max_iterations = 30;
};

/// Throws std::invalid_argument naming the first option that is not finite
/// and positive (rtol, atol, h_min, h_max, safety ∈ (0, 1], implicit_tol,
/// implicit_max_iterations ≥ 1) or h_min > h_max. makeIntegrator calls it.
void validateOptions(const IntegratorOptions& options);

struct StepResult {
  bool ok = true;            ///< false: the state became non-finite or the step fell below h_min
  double h_taken = 0;        ///< step actually taken (0 if !ok)
  double h_next = 0;         ///< suggested next step (adaptive) or the same h
  double error = 0;          ///< scaled error norm of the accepted step (adaptive; 0 otherwise)
  int rejected = 0;          ///< rejected attempts before acceptance
  int evaluations = 0;       ///< calls to the field
  const char* failure = nullptr;  ///< why !ok, when the method can say (static text)
  /// ∫ rate(i) dt over the accepted step, by the method's own quadrature
  /// (its stages and weights); zero past the field's rateCount().
  std::array<double, AccelerationField::kMaxRates> integrals{};
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual IntegratorType type() const = 0;
  virtual bool adaptive() const { return false; }
  /// One step from (t, q, v) with step h (the first attempt, for adaptive
  /// methods). On success t, q, v are advanced; on failure they are untouched.
  virtual StepResult step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) = 0;
  /// Forget any state carried between steps (the FSAL stage); call after the
  /// caller changes q or v itself (an impulse, a new state).
  virtual void reset() {}
  /// The caller moved the accepted state by (Δθ, Δv) — local coordinates
  /// around the old q, and the velocity change — to put it back on the
  /// constraints (the simulator's drift projection). By default that forgets
  /// the carried stages, as reset(). Dormand–Prince keeps its FSAL stage when
  /// the move is within its error tolerance (integrators.cpp).
  virtual void stateMoved(const VecX& dtheta, const VecX& dv) {
    (void)dtheta, (void)dv;
    reset();
  }
  /// Dense output of the last accepted step: the state at t₀ + s·h, s ∈ [0, 1]
  /// (a continuous extension of the method's own stages, no new evaluation).
  /// Returns false when the method has none or no step was accepted since.
  virtual bool denseOutput(double s, VecX& q, VecX& v) {
    (void)s, (void)q, (void)v;
    return false;
  }
};

/// Throws std::invalid_argument for options validateOptions() refuses.
std::unique_ptr<Integrator> makeIntegrator(IntegratorType type, const Model& model,
                                           const IntegratorOptions& options = {});

}  // namespace appell
