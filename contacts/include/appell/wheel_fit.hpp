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
};

/// Fits the rolling shape of `vertices` (link frame) about the axle through
/// `axle_point` along `axle` (unit). Throws std::invalid_argument when the
/// mesh has fewer than 3 vertices, lies on the axle, or has no width.
WheelFit fitWheel(const std::vector<Vec3>& vertices, const Vec3& axle_point, const Vec3& axle);

}  // namespace appell
