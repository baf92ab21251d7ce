// Row writers of the contact kinds (one file each), given the geometry.
#pragma once

#include <appell/constraint.hpp>
#include <appell/contact_geometry.hpp>

namespace appell::detail {

/// Writes a row into `out` at index k.
void putRow(RowBlock& out, int k, const Vec6& w, double b, double kappa, double gap);

/// Rolling: tangent1, tangent2, normal (+ spin when `no_spin`).
void writeRollingRows(const ContactGeometry& g, const Vec6& V, const SupportState& S, bool no_spin,
                      RowBlock& out);

/// Knife edge: lateral, normal. `blade_body` is the blade direction in the body
/// frame (point blades) or, when `wheel_axis` is true, the wheel axle, whose
/// in-plane projection is the lateral direction. Returns the singular reason or nullptr.
const char* writeKnifeEdgeRows(const ContactGeometry& g, const SE3& pose, const Vec6& V,
                               const SupportState& S, const Vec3& blade_body, bool wheel_axis,
                               double tol, RowBlock& out);

/// Sliding: normal only.
void writeSlidingRows(const ContactGeometry& g, const Vec6& V, const SupportState& S,
                      RowBlock& out);

}  // namespace appell::detail
