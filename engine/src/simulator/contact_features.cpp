// Contacts on piecewise supports: a terrain's flat regions, edges and
// vertices (contacts/include/appell/terrain.hpp).
//
// The nearest piece of a terrain changes where a wheel passes from a face to
// an edge, from an edge to the next face, or where a rising face overtakes
// the one it rolls on. There the normal's rate jumps (the surface's curvature
// does), and at a concave crease the normal velocity jumps (an impact). Left
// to each evaluation's nearest-piece search, such a switch falls between the
// stages of a step; a rigid car whose two front wheels cross an edge a
// round-off apart then sees one wheel on the face and the other on the edge,
// and its redundant normal rows (four wheels, three heave/roll/pitch freedoms)
// disagree by the jump in curvature: the step size collapses.
//
// So the piece is a mode, like open/closed and sticking/sliding (Pfeiffer &
// Glocker 1996, ch. 5): between events every closed contact is evaluated on
// its latched piece, extended past its bounds (TerrainPiece::latched),
// and the dynamics are smooth. After each step one search with the latches
// off finds each contact's nearest piece; a closed contact whose nearest
// piece is neither its latched one nor the one it had at the step's start has
// switched, and the switch is an event located like a touchdown (bisection on
// "some contact switched", on the dense output). At the event every contact
// that switched takes its new piece, and so does every contact that switches
// within `feature_window` after it (its lookahead piece): the car's two front
// wheels change together. Then the modes are decided as at a touchdown — a
// contact that now approaches its new piece takes an impact.
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

namespace appell {

using detail::UnilateralRow;

/// Closed contacts use their latched piece; open ones search (their gap is
/// the distance to the nearest piece, the touchdown's event function).
///
/// Points of one pair (Constraint::pointGroup): of the open points only the
/// lowest slot watches — the others idle (dormant), or all would touch down
/// on one piece together. The watcher's search skips the pieces the closed
/// points hold: it finds the nearest *separate* piece, a second place the
/// body may touch. A closed point's search skips the other closed points'
/// pieces and the watcher's: where the body reaches the watched piece (a
/// ball sliding down one slope of a valley meets the other) that is the
/// watcher's touchdown, not a jump of the closed point onto it.
void Simulator::Impl::applyLatches() {
  auto& rows = uni_->rows;
  for (UnilateralRow& r : rows) {
    if (r.joint) continue;
    r.dormant = false;
    if (cdata_->isActive(r.c)) continue;
    for (int j : r.siblings)
      if (!cdata_->isActive(rows[j].c) && rows[j].slot < r.slot) r.dormant = true;
  }
  for (UnilateralRow& r : rows) {
    if (r.joint) continue;
    RowBlock& blk = cdata_->blocks[r.c];
    const bool closed = cdata_->isActive(r.c);
    blk.piece.latched = closed ? r.feature : -1;
    blk.piece.excluded_count = 0;
    for (int j : r.siblings) {
      const UnilateralRow& s = rows[j];
      const bool held = cdata_->isActive(s.c), watched = closed && !held && !s.dormant;
      if ((held || watched) && s.feature >= 0)
        blk.piece.excluded[blk.piece.excluded_count++] = s.feature;
    }
  }
}

/// Whether closed row r has moved to a piece that is neither its latched one
/// nor the one it had at the step's start (after searchFeatures). A search
/// that found no separate piece in reach (−1) is no switch.
static bool switched(const UnilateralRow& r) {
  return r.feature_free >= 0 && r.feature_free != r.feature && r.feature_free != r.feature_start;
}

/// Searches every contact's nearest piece at (t_, q_, v_) into feature_free
/// (the rows in cdata_ are then the searched ones) and restores the latches.
/// Returns the first closed row that switched, or −1.
int Simulator::Impl::searchFeatures() {
  auto& u = *uni_;
  for (const UnilateralRow& r : u.rows)
    if (!r.joint) cdata_->blocks[r.c].piece.latched = -1;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  int first = -1;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    UnilateralRow& r = u.rows[k];
    if (r.joint) continue;
    r.feature_free = cdata_->blocks[r.c].piece.feature;
    if (first < 0 && cdata_->isActive(r.c) && switched(r)) first = k;
  }
  applyLatches();
  return first;
}

/// Whether the searched rows in cdata_ are every closed contact's latched
/// ones (after searchFeatures): then they need no re-evaluation.
bool Simulator::Impl::searchedRowsLatched() const {
  for (const UnilateralRow& r : uni_->rows)
    if (!r.joint && cdata_->isActive(r.c) && r.feature != r.feature_free) return false;
  return true;
}

/// After a step with no switch: the pieces searched at its end are the next
/// step's starting ones; an open contact follows its nearest piece.
void Simulator::Impl::acceptFeatures() {
  for (UnilateralRow& r : uni_->rows) {
    if (r.joint) continue;
    r.feature_start = r.feature_free;
    if (!cdata_->isActive(r.c)) r.feature = r.feature_free;
  }
  applyLatches();
}

/// At an event (t_, q_, v_): every closed contact that switched — or, with
/// `lookahead`, switches within feature_window (the pieces searched then are
/// in feature_ahead) — takes its new piece (a Feature event each); an open
/// one follows its nearest piece; the pieces now are the next step's
/// starting ones.
void Simulator::Impl::switchFeatures(bool lookahead) {
  auto& u = *uni_;
  searchFeatures();
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    UnilateralRow& r = u.rows[k];
    if (r.joint) continue;
    const int ahead = u.feature_ahead[k];
    int next = r.feature;
    if (!cdata_->isActive(r.c)) next = r.feature_free;
    else if (switched(r)) next = r.feature_free;
    else if (lookahead && ahead >= 0 && ahead != r.feature && ahead != r.feature_start &&
             ahead != r.feature_free)
      next = ahead;
    const bool logged = cdata_->isActive(r.c) && next != r.feature;
    r.feature = next;
    r.feature_start = r.feature_free;
    if (logged) {
      logEvent(ContactEventKind::Feature, k, 0, 0, 0);
      events_.back().feature = next;
    }
  }
  applyLatches();
}

}  // namespace appell
