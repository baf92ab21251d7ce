// Frictionless sliding support: only the gap row, ġ = nᵀ(V_B(x) − V_S(x)) = 0.
#include "contact_kinds.hpp"
#include "contact_rows.hpp"

namespace appell::detail {

void writeSlidingRows(const ContactGeometry& g, const Vec6& V, const SupportState& S,
                      RowBlock& out) {
  const RowTerms rn = pointVelocityRow(g.normal, g.normal_rate, g.point, g.point_rate, V, S);
  putRow(out, 0, rn.w, rn.b, rn.kappa, g.gap);
}

}  // namespace appell::detail
