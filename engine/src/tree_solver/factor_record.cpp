// Tree solver, reuse of the factor: factorPassIfChanged runs the factor pass
// (backward.cpp) only when the rows it factors changed — the tree rows'
// body-frame coefficients, the joint rows' activity and coefficient, and the
// configuration — and otherwise keeps the last factor, which is then the
// same bit for bit. The record (workspace.hpp, FactorRecord) is sized once by
// the solver's constructor: no allocation here.
#include "tree_solver/workspace.hpp"

#include <algorithm>
#include <utility>

namespace appell::detail {

void factorPassIfChanged(const Model& model, const Data& data, const ConstraintData& cdata,
                         const VecX& q, TreeWorkspace& ws) {
  FactorRecord& rec = ws.factor_record;
  int n = 0;
  for (const TreeBlock& tb : ws.blocks) {
    rec.next[n++] = tb.rows;
    const RowBlock& blk = cdata.blocks[tb.constraint];
    const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
    for (int r = 0; r < tb.rows; ++r)
      for (int c = 0; c < 6; ++c) rec.next[n++] = W(r, c);
  }
  for (int b : ws.jrow_nodes)
    for (const JointRow& jr : ws.nodes[b].jrows) {
      const bool active = cdata.isActive(jr.constraint);
      rec.next[n++] = active ? 1.0 : 0.0;
      rec.next[n++] = active ? cdata.blocks[jr.constraint].A_joint(jr.row, 0) : 0.0;
    }
  const int tree_length = n;
  const int capacity = static_cast<int>(rec.next.size());
  bool fits = true;  // a joint-space row's columns are sized by its ConstraintData
  for (const LoopRow& lr : ws.loops) {
    const RowBlock& blk = cdata.blocks[lr.constraint];
    if (lr.joint_space) {
      const int cols = static_cast<int>(blk.joint_cols.size());
      fits = fits && n + 1 + cols <= capacity;
      if (!fits) break;
      rec.next[n++] = cols;
      for (int c = 0; c < cols; ++c) rec.next[n++] = blk.A_joint(lr.row, c);
    } else {
      for (int c = 0; c < 6; ++c) rec.next[n++] = blk.Wa(lr.row, c);
      for (int c = 0; c < 6; ++c) rec.next[n++] = blk.Wb(lr.row, c);
    }
  }
  auto equal = [&](int from, int to) {
    return std::equal(rec.next.begin() + from, rec.next.begin() + to, rec.rows.begin() + from);
  };
  const bool tree_same = rec.valid && tree_length == rec.tree_length && rec.q == q &&
                         equal(0, tree_length);
  const bool loops_same = tree_same && fits && n == rec.length && equal(tree_length, n);
  ws.last_factor_reused = tree_same;
  if (!loops_same) ws.loop_closure_valid = false;
  if (!tree_same) factorPass(model, data, cdata, ws);
  else ws.redundant = rec.redundant;  // what factorPass set; the callers add to it
  if (loops_same) return;
  std::swap(rec.rows, rec.next);  // same capacity: no allocation
  rec.tree_length = tree_length;
  rec.length = n;
  rec.q = q;
  rec.redundant = ws.redundant;
  rec.valid = fits;
}

}  // namespace appell::detail
