// Unilateral constraints: contacts that make and break, as events.
//
// A unilateral constraint (Constraint::unilateralRow() ≥ 0: contacts, joint
// limits) is closed — all its rows hold, the row u is ġ of a gap g ≥ 0 and
// its multiplier must push, λᵤ ≥ 0 — or open (no rows; g > 0). Between
// events the active set is fixed and the motion is the smooth constrained
// dynamics of the closed rows (exact rolling). The complementarity
//     g ≥ 0,  λᵤ ≥ 0,  g λᵤ = 0
// is met by switching modes at events (the event-driven scheme of Pfeiffer &
// Glocker, "Multibody Dynamics with Unilateral Contacts", Wiley 1996, ch. 5–7):
//
//   touchdown   an open gap reaches 0           g(t*) = 0
//   lift-off    a closed contact's λᵤ reaches 0  λᵤ(t*) = 0
//
// located by root finding on the event functions g(t), λᵤ(t) over the step
// (the step is then shortened to end at t*: every integrator's last step is
// a proper step of the method). At t* all touching contacts are decided
// together, in two complementarity problems:
//
//  1. Impact (velocity level), if a touching contact approaches (γ = ġ < 0):
//     Newton's law per contact, impulses Λᵤ ≥ 0,
//         γ⁺ + e γ⁻ ≥ 0,  Λᵤ ≥ 0,  (γ⁺ + e γ⁻) Λᵤ = 0,
//     with every other row of a contact that takes an impulse (no-slip of a
//     rolling contact) holding after the impact. The impulse for a given set
//     is the velocity projection's: v⁺ = argmin ‖v⁺ − v‖_M subject to the
//     closed rows (Moreau 1988; the same solver as the drift control, so a
//     plastic rolling impact conserves the angular momentum about the
//     contact point). Contacts that rebound (e γ⁻ > 0) leave open. Below
//     `rest_speed` an impact is plastic, so a bouncing sequence ends after
//     finitely many impacts (no Zeno accumulation).
//  2. Contact forces (acceleration level), for the touching contacts at rest:
//         γ̇ ≥ 0,  λᵤ ≥ 0,  γ̇ λᵤ = 0,
//     where γ̇ of an open contact is its normal acceleration. Both problems are
//     linear complementarity problems in the Delassus operator A M⁻¹ Aᵀ; they
//     are solved by principal pivoting on the active set with Murty's
//     least-index rule (Murty, "Note on a Bard-type scheme for solving the
//     complementarity problem", Opsearch 11, 1974), each pivot one solve of the
//     chosen formulation — so the tree solver stays O(n) and the three
//     formulations decide the same modes. Finite for a P-matrix (independent
//     normal rows); with redundant rows (a box on four corners) the
//     minimum-norm λ keeps the pivoting well defined, and a set not found in
//     `max_mode_iterations` pivots is an error naming the contacts.
#pragma once

#include <appell/name_table.hpp>

#include <limits>
#include <string>
#include <vector>

namespace appell {

enum class ContactEventKind {
  Touchdown,  ///< an open contact's gap reached 0; it closed (after the impact, if any)
  Bounce,     ///< it touched down and rebounded (restitution): it stays open
  LiftOff,    ///< a closed contact's normal force reached 0; it opened
  Slip,       ///< a sticking contact's friction demand reached μ: it slides
  Stick,      ///< a sliding contact's slip stopped and sticking holds: it sticks
  Feature,    ///< a closed contact moved onto another face, edge or vertex of a terrain
  /// The automatic scheme opened a time-stepping window (docs/contacts.md §10);
  /// `constraint` is the contact whose mode decision failed or whose events
  /// piled up (the first unilateral one when the step collapsed).
  TimeStepping,
  Events,     ///< the window closed: the event scheme decided the modes again
};
/// "touchdown", "bounce", "lift_off", "slip", "stick", "feature",
/// "timestepping", "events": the names of the run summary and CSV.
std::span<const NamedValue<ContactEventKind>> contactEventKindTable();
const char* toString(ContactEventKind kind);

struct ContactEvent {
  double t = 0;
  int constraint = -1;            ///< index in the simulator's ConstraintList
  ContactEventKind kind = ContactEventKind::Touchdown;
  double speed_before = 0;        ///< normal velocity γ = ġ before (negative: approaching)
  double speed_after = 0;         ///< after the impact
  double normal_impulse = 0;      ///< Λᵤ ≥ 0 (0 without an impact)
  double tangential_impulse = 0;  ///< |impulse of the tangent/lateral rows| (friction demand)
  int feature = -1;               ///< Feature: the piece it moved onto (RowBlock::feature)
};

struct ContactEventOptions {
  /// false: unilateral constraints never open (every contact is the
  /// bilateral idealisation; lift-off is only reported).
  bool enabled = true;
  double gap_tol = 1e-9;          ///< touching: |g| ≤ gap_tol at an event or at t = 0
  double speed_tol = 1e-9;        ///< |γ| ≤ speed_tol: at rest, no impact
  double force_tol = 1e-9;        ///< λᵤ < −force_tol pulls (lift-off)
  double time_tol = 1e-12;        ///< events located to this (s)
  /// Impacts slower than this are plastic, and a contact that an impact
  /// would unload into separating slower than this is held: a bouncing or
  /// rocking body comes to rest after finitely many impacts (docs/contacts.md §7).
  double rest_speed = 1e-3;
  /// A sliding contact whose slip direction settles faster than this —
  /// |s| / (μₖλₙ‖W‖) with W its rows' Delassus operator: a tiny slip that a
  /// misaligned axle forces, a slip just starting — slides along its settled
  /// direction, the force on the friction circle that makes the slip
  /// accelerate along itself, instead of integrating that direction's
  /// relaxation (rate 1/settle_time and faster: docs/contacts.md §8). 0: never.
  double settle_time = 1e-4;
  /// A closed contact on a terrain stays on its face, edge or vertex
  /// (extended past its bounds) between events; reaching another is an event.
  /// Contacts that reach theirs within this time of the first one switch
  /// with it: a rigid car's two wheels crossing an edge side by side, a
  /// round-off apart, must not see each other on different pieces
  /// (docs/contacts.md §4). A switch early by δ = speed · window moves a
  /// rolling body by O(δ²/radius).
  double feature_window = 1e-6;
  int max_mode_iterations = 64;   ///< pivots of one complementarity problem
  int max_locate_iterations = 60; ///< root-finding iterations per event
};

namespace detail {
struct UnilateralState;  // the simulator's per-contact workspace (simulator_internal.hpp)
}

}  // namespace appell
