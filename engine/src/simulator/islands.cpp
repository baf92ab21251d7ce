// Islands: the unilateral rows grouped by the bodies their forces can move.
//
// The world does not move, so the bodies hanging from it split into trees
// (a root body whose parent is the world, and everything below it) whose
// dynamics are independent: a force on one tree accelerates no other. Two
// trees are coupled only by a constraint that acts on both — a loop joint, a
// mimic between their joints, a contact between two of their bodies. The
// union of the trees that constraints couple (union–find over the trees;
// Tarjan, "Efficiency of a good but not linear set union algorithm", JACM 22,
// 1975) is an island: a force anywhere in it moves only its bodies.
//
// Every friction problem (the onset, the settled directions, an impact's
// impulses, over-constrained sticking, the sliding normal loads) couples its
// contacts through the Delassus operator of their rows, and that operator
// has no entry between two islands. So each problem is solved island by
// island, on storage sized for the largest island, not for every contact of
// the scene: 3 000 balls, each its own island, need 3 000 problems of one
// contact each, not one of 3 000 contacts with a 6 000 × 6 000 operator
// (docs/hardening.md, "Memory"). A scene that is one island (a car, a robot)
// solves its one problem exactly as before, on the same storage.
//
// The islands are fixed at construction from which bodies each constraint
// may act on (its bodies, or a joint-space row's columns), open or closed:
// a contact that is open now still couples what it may touch later.
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <numeric>

namespace appell {

namespace {

/// The tree of body b: its ancestor whose parent is the world (−1 for the world).
int treeOf(const Model& model, int b) {
  if (b < 0) return -1;
  while (model.parent[b] >= 0) b = model.parent[b];
  return b;
}

int findRoot(std::vector<int>& up, int x) {
  while (up[x] != x) x = up[x] = up[up[x]];  // path halving
  return x;
}

}  // namespace

detail::Islands detail::findIslands(const Model& model, const ConstraintList& constraints,
                                    const ConstraintData& cd,
                                    const std::vector<UnilateralRow>& rows) {
  const int nb = static_cast<int>(model.parent.size());
  std::vector<int> up(nb);
  std::iota(up.begin(), up.end(), 0);
  // The first tree each constraint touches, and every other joined to it.
  std::vector<int> first(constraints.size(), -1);
  for (int c = 0; c < static_cast<int>(constraints.size()); ++c) {
    const Constraint& con = *constraints[c];
    auto join = [&](int tree) {
      if (tree < 0) return;
      if (first[c] < 0) first[c] = tree;
      else up[findRoot(up, tree)] = findRoot(up, first[c]);
    };
    if (con.jointSpace())
      for (int col : cd.blocks[c].joint_cols) join(treeOf(model, model.body_of_v[col]));
    else {
      join(treeOf(model, con.bodyA()));
      join(treeOf(model, con.bodyB()));
    }
  }
  // Islands numbered in the order of their first unilateral row; a row that
  // touches no moving body is an island of its own.
  Islands is;
  const int n = static_cast<int>(rows.size());
  is.of_row.assign(n, -1);
  std::vector<int> island_of_root(nb, -1);
  int count = 0;
  for (int k = 0; k < n; ++k) {
    const int tree = first[rows[k].c];
    if (tree < 0) {
      is.of_row[k] = count++;
      continue;
    }
    int& id = island_of_root[findRoot(up, tree)];
    if (id < 0) id = count++;
    is.of_row[k] = id;
  }
  // Rows island by island, in their order inside each.
  is.start.assign(count + 1, 0);
  for (int k = 0; k < n; ++k) ++is.start[is.of_row[k] + 1];
  std::partial_sum(is.start.begin(), is.start.end(), is.start.begin());
  is.rows.resize(n);
  std::vector<int> fill(is.start.begin(), is.start.end() - 1);
  for (int k = 0; k < n; ++k) is.rows[fill[is.of_row[k]]++] = k;
  for (int i = 0; i < count; ++i) {
    int contacts = 0, friction_rows = 0;
    for (int j = is.start[i]; j < is.start[i + 1]; ++j)
      if (rows[is.rows[j]].nf > 0) {
        ++contacts;
        friction_rows += rows[is.rows[j]].nf;
      }
    is.max_friction_contacts = std::max(is.max_friction_contacts, contacts);
    is.max_friction_rows = std::max(is.max_friction_rows, friction_rows);
  }
  return is;
}

}  // namespace appell
