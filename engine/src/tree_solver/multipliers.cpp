// Tree solver, multipliers: unrolling the row compressions with their
// adjoints, the reaction Aᵀλ in O(n + m), and the certificate that names the
// constraints behind an inconsistency.
//
// A compression replaced the stacked rows B (right sides r) by K = Q₁ᵀ E B,
// so a multiplier μ on K is the force Kᵀμ = Bᵀ(E Q₁ μ): the stacked rows get
// λ = E Q₁ μ. Dropped rows (redundant) get exactly the share E Q₁ μ assigns
// them — Aᵀλ and v̇ are exact, λ is one solution; tree_solver/min_norm.cpp
// then makes it the minimum-norm one when rows are redundant.
#include "tree_solver/workspace.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace appell::detail {

namespace {

/// Hands the stacked-row multipliers `lam` of compression `e` to their owners.
void distribute(TreeWorkspace& ws, Node& nd, int e, const BufVec& lam, VecX& lambda) {
  const Compression& cp = nd.comp[e];
  const double* in = lam.data();
  for (int s = 0; s < cp.nseg; ++s) {
    const Segment& g = cp.seg[s];
    double* out;
    if (g.kind == Segment::Previous) {
      KVec& mu = nd.comp[e - 1].mu;
      mu.resize(g.rows);
      out = mu.data();
    } else if (g.kind == Segment::Block) {
      out = lambda.data() + ws.blocks[g.id].global;
    } else {
      KVec& nu = ws.nodes[g.id].nu;
      nu.resize(g.rows);
      out = nu.data();
    }
    for (int k = 0; k < g.rows; ++k) out[k] = in[k];
    in += g.rows;
  }
}

}  // namespace

void unrollNode(TreeWorkspace& ws, int body, int from, VecX& lambda) {
  Node& nd = ws.nodes[body];
  for (int e = from; e >= 0; --e) {
    const Compression& cp = nd.comp[e];
    BufVec lam(cp.nrows);
    for (int k = 0; k < cp.nrows; ++k) lam[k] = k < cp.rank ? cp.mu[k] : 0.0;
    if (cp.soft) softDroppedMultipliers(cp, lam);
    applyQ(cp, lam);
    for (int k = 0; k < cp.nrows; ++k) lam[k] *= cp.E[k];
    distribute(ws, nd, e, lam, lambda);
  }
}

void reactionForces(const Model& model, const Data& data, const ConstraintData& cdata,
                    TreeWorkspace& ws, const VecX& lambda, VecX& reaction) {
  for (auto& f : ws.fsub) f.setZero();
  // Each row is a world spatial covector, i.e. a spatial force on its body.
  for (const TreeBlock& tb : ws.blocks) {
    const RowBlock& blk = cdata.blocks[tb.constraint];
    const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
    Vec6& f = ws.fsub[tb.body];
    for (int r = 0; r < tb.rows; ++r)  // W's rows as fixed-size 6-vectors
      f += (tb.sign * lambda[tb.global + r]) * Eigen::Map<const Vec6>(W.data() + 6 * r);
  }
  reaction.setZero();
  for (const LoopRow& lr : ws.loops) {
    const RowBlock& blk = cdata.blocks[lr.constraint];
    const double l = lambda[lr.global];
    if (lr.joint_space) {
      addJointRow(blk, lr.row, l, reaction);
      continue;
    }
    ws.fsub[lr.bodyA] += l * blk.Wa.row(lr.row).transpose();
    ws.fsub[lr.bodyB] -= l * blk.Wb.row(lr.row).transpose();
  }
  for (int b : ws.jrow_nodes)  // rows on one joint's velocity: c λ on it
    for (const JointRow& r : ws.nodes[b].jrows)
      if (r.active) reaction[model.joints[b].idx_v] += r.c * lambda[r.global];
  for (int i = model.nbodies - 1; i >= 0; --i) {
    const int p = model.parent[i];
    const Joint& j = model.joints[i];
    if (j.nv == 1)
      reaction[j.idx_v] += j.S.col(0).dot(data.oMi[i].actInvForce(ws.fsub[i]));
    else if (j.nv > 0)
      reaction.segment(j.idx_v, j.nv).noalias() +=
          j.S.transpose() * data.oMi[i].actInvForce(ws.fsub[i]);
    if (p >= 0) ws.fsub[p] += ws.fsub[i];
  }
}

std::string describeFailure(const Model& model, const Data& data, TreeWorkspace& ws) {
  const Failure f = ws.failure;
  if (f.node < 0) return ws.last_error;  // loop closure wrote its own message
  VecX cert = VecX::Zero(ws.m);
  const int i = f.node;
  for (int j = i; j < model.nbodies; ++j)
    if (model.isAncestor(i, j)) ws.nodes[j].nu.setZero(ws.nodes[j].npass);
  Node& nd = ws.nodes[i];

  // The violated combination, pushed back to the rows it came from exactly
  // as a multiplier would be.
  if (f.comp >= 0) {
    const Compression& cp = nd.comp[f.comp];
    BufVec r;
    gatherRhs(ws, i, f.comp, r);
    r.array() *= cp.E.array();
    BufVec lam = r;
    applyQt(cp, lam);
    lam.head(cp.rank).setZero();  // Q₂ t₂: the dropped combinations only
    if (cp.soft) {  // … and of those, only the redundant ones (not fixed by compliance)
      const int nd_ = cp.nrows - cp.rank, nz = nd_ - cp.nelim;
      const auto Uz = cp.Ud.rightCols(nz);
      BufVec y(nz);
      y.noalias() = Uz.transpose() * lam.tail(nd_);
      lam.tail(nd_).noalias() = Uz * y;
    }
    applyQ(cp, lam);
    lam.array() *= cp.E.array();
    distribute(ws, nd, f.comp, lam, cert);
    if (f.comp > 0) unrollNode(ws, i, f.comp - 1, cert);
  } else {
    const Vec6 xa = data.liMi[i].actInv(ws.a_world);
    nd.nu = nd.kpass - nd.Kpass * xa;
    nd.comp[nd.ncomp - 1].mu.setZero(nd.nK);
    addU2(nd, nd.nu, nd.comp[nd.ncomp - 1].mu);
    if (nd.locked) lockedCertificate(nd, cert);
    unrollNode(ws, i, nd.ncomp - 1, cert);
  }
  for (int j = i + 1; j < model.nbodies; ++j) {
    Node& c = ws.nodes[j];
    if (!model.isAncestor(i, j) || c.ncomp == 0 || c.npass == 0) continue;
    c.comp[c.ncomp - 1].mu.setZero(c.nK);
    addU2(c, c.nu, c.comp[c.ncomp - 1].mu);
    if (c.locked) lockedCertificate(c, cert);
    unrollNode(ws, j, c.ncomp - 1, cert);
  }

  const double big = cert.lpNorm<Eigen::Infinity>();
  std::string names;
  for (const TreeBlock& tb : ws.blocks) {
    if (cert.segment(tb.global, tb.rows).lpNorm<Eigen::Infinity>() <= 1e-8 * big) continue;
    if (!names.empty()) names += ", ";
    names += "'" + ws.names[tb.constraint] + "'";
  }
  for (int b : ws.jrow_nodes)
    for (const JointRow& r : ws.nodes[b].jrows) {
      if (!r.active || std::abs(cert[r.global]) <= 1e-8 * big) continue;
      const std::string n = "'" + ws.names[r.constraint] + "'";
      if (names.find(n) != std::string::npos) continue;
      if (!names.empty()) names += ", ";
      names += n;
    }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g", f.residual);
  return "inconsistent constraints " + names + " (detected at body '" + model.body_names[i] +
         "'" + (f.comp < 0 ? ", on rows no joint can move" : "") + "; residual " + buf +
         "): no acceleration satisfies them all";
}

}  // namespace appell::detail
