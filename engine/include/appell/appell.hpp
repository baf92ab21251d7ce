// Everything the engine offers, in one include: the model and its workspace,
// the unconstrained algorithms, the constraint rows, the three constrained
// formulations behind makeSolver, drift projection, the simulator, and the
// analysis tools (equilibria, linearization). Contacts (<appell/contacts.hpp>)
// and file input/output (<appell/urdf.hpp>, <appell/output.hpp>) are separate
// libraries with their own headers.
#pragma once

// Model, workspace, configuration manifold.
#include <appell/spatial.hpp>
#include <appell/model.hpp>
#include <appell/data.hpp>
#include <appell/configuration.hpp>

// Unconstrained algorithms and integrators.
#include <appell/kinematics.hpp>
#include <appell/dynamics.hpp>
#include <appell/integrators.hpp>

// Constraint rows and the constrained formulations.
#include <appell/constraint.hpp>
#include <appell/constraint_set.hpp>
#include <appell/constrained_dynamics.hpp>
#include <appell/tree_solver.hpp>
#include <appell/kkt.hpp>
#include <appell/appell_maggi.hpp>

// Drift projection and the simulation loop.
#include <appell/actuators.hpp>
#include <appell/joint_coupling.hpp>
#include <appell/joint_limit.hpp>
#include <appell/projection.hpp>
#include <appell/simulator.hpp>
#include <appell/contact_problem.hpp>

// Analysis.
#include <appell/equilibria.hpp>
#include <appell/linearization.hpp>
