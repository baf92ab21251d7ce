// Rolling without slipping: the body point in contact moves with the support
// (two tangential nonholonomic rows) and stays on it (the normal row, ġ).
// Rolling without spin adds nᵀ(ω − Ω) = 0 ("rubber" rolling).
#include "contact_kinds.hpp"
#include "contact_rows.hpp"

namespace appell::detail {

void putRow(RowBlock& out, int k, const Vec6& w, double b, double kappa, double gap) {
  out.Wa.row(k) = w.transpose();
  out.Wb.row(k).setZero();
  out.b[k] = b;
  out.kappa[k] = kappa;
  out.gap[k] = gap;
}

void writeRollingRows(const ContactGeometry& g, const Vec6& V, const SupportState& S, bool no_spin,
                      RowBlock& out) {
  const RowTerms r1 = pointVelocityRow(g.t1, g.t1_rate, g.point, g.point_rate, V, S);
  const RowTerms r2 = pointVelocityRow(g.t2, g.t2_rate, g.point, g.point_rate, V, S);
  const RowTerms rn = pointVelocityRow(g.normal, g.normal_rate, g.point, g.point_rate, V, S);
  putRow(out, 0, r1.w, r1.b, r1.kappa, 0);
  putRow(out, 1, r2.w, r2.b, r2.kappa, 0);
  putRow(out, 2, rn.w, rn.b, rn.kappa, g.gap);
  if (no_spin) {
    const RowTerms rs = spinRow(g.normal, g.normal_rate, V, S);
    putRow(out, 3, rs.w, rs.b, rs.kappa, 0);
  }
}

}  // namespace appell::detail
