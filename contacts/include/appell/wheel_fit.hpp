// The smooth rolling shape of a wheel given as a mesh (CAD wheels).
//
// A wheel spins about its joint's axle a through the link origin. Each
// vertex p (link frame) has an axial coordinate z = a·p and a distance from
// the axle r = |p − (a·p) a|; revolving the wheel sweeps the outline
// {(z, r)}, so the rolling shape depends only on that profile:
//   outer radius R = max r, width w = max z − min z, mid-plane z_c;
//   the tread: the vertices with r ≥ R − w/2 (the outer half of a tyre whose
//   tube is as wide as the wheel);
//   the tread's profile fitted by a circle in the (z, r) half-plane
//   (algebraic least squares: z² + r² = 2 z₀ z + 2 r₀ r + c, Kåsa 1976),
//   tube radius ρ = √(c + z₀² + r₀²), tube centre (z₀, r₀).
// A rounded tread (ρ < w) is a torus about the axle: centre circle r₀, tube ρ.
// A flat or nearly flat one (ρ ≥ w: a cylinder's rim) is a disk of radius R in
// the mid-plane, as a cylinder collision is (docs/contacts.md). The fit
// reports the largest distance of a tread vertex from the fitted surface —
// chord sag and export noise for a true wheel; eccentricity (a mesh not
// centred on the axle) or a tread that is not a circle show up there.
//
// Whether the mesh is a wheel at all is its roundness about the axle: the
// runout R − d, with d the distance from the axle to the nearest edge of the
// convex outline of the vertices projected across the axle (a regular
// N-gon: R(1 − cos π/N), its chord sag; a wheel off centre by e adds
// e(1 + cos π/N) ≈ 2e, the total runout of engineering drawings; a foot
// about its ankle is most of R). isWheel accepts a fit
// whose runout — and, for a torus, the tread's deviation from its circle —
// is at most kWheelTolerance = 2 % of R: a 16-gon's sag is 1.9 %, so any
// wheel tessellated at least that finely passes, while a shape that is not
// round (an ankle or a sole, tens of % of R) fails by an order of magnitude.
#pragma once

#include <appell/shapes.hpp>

#include <array>
#include <vector>

namespace appell {

struct WheelFit {
  Shape shape;               ///< Disk or Torus, link frame
  bool torus = false;
  double outer_radius = 0;   ///< R: the largest distance of a vertex from the axle
  double tube_radius = 0;    ///< ρ of the torus (0 for a disk)
  double width = 0;          ///< extent along the axle
  double max_deviation = 0;  ///< largest distance of a tread vertex from the shape
  int tread_vertices = 0;
  /// R minus the distance from the axle to the nearest edge of the convex
  /// outline across the axle (≥ R when the axle lies outside the outline).
  double runout = 0;
};

/// The largest out-of-roundness a wheel may have, as a fraction of its outer radius.
inline constexpr double kWheelTolerance = 0.02;

/// Whether a fit is a wheel: runout and (torus) tread deviation at most
/// kWheelTolerance · outer radius.
bool isWheel(const WheelFit& fit);

/// Fits the rolling shape of `vertices` (link frame) about the axle through
/// `axle_point` along `axle` (unit). Throws std::invalid_argument when the
/// mesh has fewer than 3 vertices, lies on the axle, or has no width.
WheelFit fitWheel(const std::vector<Vec3>& vertices, const Vec3& axle_point, const Vec3& axle);

}  // namespace appell
