// Tree solver, forward pass (root → leaves): accelerations, then each body's
// multipliers from its joint force balance, unrolled into its rows and its
// children's handed-up rows (tree_solver/multipliers.cpp).
#include "tree_solver/workspace.hpp"

#include <algorithm>

namespace appell::detail {

bool forwardPass(const Model& model, const Data& data, TreeWorkspace& ws, bool check) {
  const SolverOptions& o = ws.options;
  for (int i = 0; i < model.nbodies; ++i) {
    Node& nd = ws.nodes[i];
    const Joint& j = model.joints[i];
    const int p = model.parent[i];

    Vec6 xa = p >= 0 ? data.liMi[i].actInv(ws.nodes[p].a) : data.liMi[i].actInv(ws.a_world);
    Vec6 abar = xa;
    if (ws.use_c) abar += nd.c;

    if (p < 0 && nd.npass > 0) {
      // Rows no joint can move act on the world's (prescribed) acceleration:
      // they must already hold. Their combinations are zero rows of A, whose
      // multipliers are free: zero here, then chosen by tree_solver/min_norm.cpp.
      nd.nu.setZero(nd.npass);
      if (check) {
        KVec lhs(nd.npass);
        lhs.noalias() = nd.Kpass * xa;
        const double res = (nd.kpass - lhs).lpNorm<Eigen::Infinity>();
        const double scale =
            std::max({1.0, nd.kpass.lpNorm<Eigen::Infinity>(), lhs.lpNorm<Eigen::Infinity>()});
        if (res > o.consistency_tol * scale) {
          ws.failure = {true, i, -1, res};
          return false;
        }
      }
    }

    if (nd.locked) {  // q̈ = ρ fixed by the joint's closed rows (tree_solver/locked.cpp)
      abar += nd.rho * j.S.col(0);
      if (nd.soft) {
        softForward(lockedJoint(), nd, abar, ws.vdot);
      } else {
        nd.a = abar;
        if (nd.ncomp > 0) {
          KVec& mu = nd.comp[nd.ncomp - 1].mu;
          mu.setZero(nd.nK);
          if (nd.npass > 0) addU2(nd, nd.nu, mu);
        }
      }
      ws.vdot[j.idx_v] = nd.rho;
      if (!ws.multipliers) continue;
      lockedForce(j, nd, ws.tau[j.idx_v], ws.lambda);
      if (nd.ncomp > 0) unrollNode(ws, i, nd.ncomp - 1, ws.lambda);
      continue;
    }
    if (nd.soft) {
      softForward(j, nd, abar, ws.vdot);
      if (ws.multipliers) unrollNode(ws, i, nd.ncomp - 1, ws.lambda);
      continue;
    }

    // q̈ = G⁺(k − K ā) + V₂ z,   z = D⁻¹(u − Uᵀ w),   w = ā + S G⁺(k − K ā).
    auto qdd = ws.vdot.segment(j.idx_v, j.nv);
    const auto tau = ws.tau.segment(j.idx_v, j.nv);
    Vec6 w = abar;
    if (nd.rankG > 0 && j.nv == 1) {
      double y = 0;  // G⁺(k − K ā), K's rows as fixed-size 6-vectors
      for (int r = 0; r < nd.nK; ++r)
        y += nd.gp[r] * (nd.k[r] - Eigen::Map<const Vec6>(nd.K.data() + 6 * r).dot(abar));
      w += y * j.S.col(0);
      qdd[0] = y;
    } else if (nd.rankG > 0) {
      KVec r = nd.k;
      r.noalias() -= nd.K * abar;
      KVec y(j.nv);
      y.noalias() = nd.Gpinv * r;
      w.noalias() += j.S * y;
      qdd = y;
    } else {
      qdd.setZero();
    }
    Vec6 a = w;
    if (nd.nf > 0) {
      KVec z = nd.u;
      z.noalias() -= nd.U.transpose() * w;
      KVec zz;
      if (nd.dinv_factor) {
        zz = z;
        nd.Dinv.triangularView<Eigen::Lower>().solveInPlace(zz);
        nd.Dinv.transpose().triangularView<Eigen::Upper>().solveInPlace(zz);
      } else {
        zz.noalias() = nd.Dinv * z;
      }
      a.noalias() += nd.S2 * zz;
      if (nd.rankG > 0)
        qdd.noalias() += nd.V2 * zz;
      else
        qdd += zz;
    }
    nd.a = a;

    // Multipliers of K from the joint's force balance  Gᵀ μ = Sᵀ f − τ with
    // f = IA a + pA (the force the joint transmits, constraint forces of
    // this body's rows excluded); the U₂ part comes from the parent. The
    // accelerations above never read them: skipped when only v̇ is asked for.
    if (nd.ncomp > 0 && ws.multipliers) {
      KVec& mu = nd.comp[nd.ncomp - 1].mu;
      mu.setZero(nd.nK);
      if (nd.rankG > 0 && j.nv == 1) {
        const Vec6 s = j.S.col(0);
        const double sIAa = p >= 0 ? nd.ias.dot(a) : s.dot(nd.IA * a);  // IA s kept (not at the root)
        mu.noalias() += (sIAa + s.dot(nd.pA) - tau[0]) * nd.gp;
      } else if (nd.rankG > 0) {
        KVec r(j.nv);
        if (nd.nf == 0 && p >= 0)  // Ia = IA, so Sᵀ IA a = (Ia S)ᵀ a, kept by the factor pass
          r.noalias() = nd.IaS.transpose() * a;
        else
          r.noalias() = j.S.transpose() * (nd.IA * a);
        r.noalias() += j.S.transpose() * nd.pA;
        r -= tau;
        mu.noalias() += nd.Gpinv.transpose() * r;
      }
      if (nd.npass > 0) addU2(nd, nd.nu, mu);
      unrollNode(ws, i, nd.ncomp - 1, ws.lambda);
    }
  }
  return true;
}

}  // namespace appell::detail
