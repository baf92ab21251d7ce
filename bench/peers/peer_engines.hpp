// The peers' side of the comparison: each function builds its engine's model of
// the disk (disk_problem.hpp), runs it from the problem's initial state and
// reports the states at 1 s and 10 s. Compiled only when the engine's Debian
// package is installed (bench/peers/CMakeLists.txt); the macros say which are.
#pragma once

#include "disk_problem.hpp"

namespace peers {

#ifdef PEERS_HAVE_SIMBODY
/// Simbody 3.7, thin disk: a free body with a Constraint::Custom rim contact
/// (one holonomic height row, two nonholonomic no-slip rows). `method` is
/// "merson" (RungeKuttaMersonIntegrator) or "rk3" (RungeKutta3Integrator),
/// run at `accuracy` (the constraint tolerance follows it, Simbody's default).
PeerRun runSimbody(const DiskProblem& p, const std::string& method, double accuracy);
/// CPU seconds of one realize(Acceleration) from a changed state (the dynamics
/// evaluation an integrator stage costs), median of `n` batches.
double simbodyEvaluationSeconds(const DiskProblem& p, int n);
#endif

#ifdef PEERS_HAVE_MUJOCO
/// MuJoCo 2.2.2: the disk as a cylinder of half-height p.half_thickness with the
/// thin disk's inertia, a free joint, stiff soft contact (solref time constant
/// 2·dt, MuJoCo's stiffest recommended), semi-implicit Euler at step `dt`.
/// With `diagnostics`, also the slip speed and penetration over the run
/// (not for timing: they are computed every step).
PeerRun runMujoco(const DiskProblem& p, double dt, int noslip, bool diagnostics);
/// CPU seconds of one mj_forward at the initial state, median of `n` batches.
double mujocoForwardSeconds(const DiskProblem& p, double dt, int n);
#endif

}  // namespace peers
