// No heap allocation inside TreeSolver::solve() and projectVelocity() once the
// result vectors have their sizes: every allocation of this executable is
// counted (operator new and malloc & co., which Eigen uses), and the count
// over repeated solves must be zero — on random trees with redundant rows,
// with loop rows, and on a pose that triggers refinement.
#include "test_tree_solver_common.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
inline void note() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
}
}  // namespace

extern "C" {
void* malloc(size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t s) {
  note();
  return __libc_calloc(n, s);
}
void* realloc(void* p, size_t n) {
  note();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* aligned_alloc(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
void* memalign(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
int posix_memalign(void** out, size_t align, size_t n) {
  note();
  *out = __libc_memalign(align, n);
  return *out ? 0 : ENOMEM;
}
}

void* operator new(size_t n) {
  note();
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n) { return operator new(n); }
void* operator new(size_t n, std::align_val_t a) {
  note();
  if (void* p = __libc_memalign(static_cast<size_t>(a), n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, size_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, size_t, std::align_val_t) noexcept { __libc_free(p); }

using namespace appell;
using namespace appell::test;

namespace {

template <typename F>
long allocationsIn(F&& fn, int reps = 10) {
  fn();
  g_allocations = 0;
  g_counting = true;
  for (int r = 0; r < reps; ++r) fn();
  g_counting = false;
  return g_allocations.load();
}

void expectNoAllocation(System& s) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  TreeSolver solver(s.model, list);
  ConstrainedResult out;
  EXPECT_EQ(allocationsIn([&] { solver.solve(s.model, data, list, cd, s.q, s.v, s.tau, out); }), 0);
  EXPECT_TRUE(out.ok) << out.error;
  VecX v, mu(cd.m);
  EXPECT_EQ(allocationsIn([&] {
              v = s.v;  // same size: no allocation
              solver.projectVelocity(s.model, data, list, cd, s.q, v, mu);
            }),
            0);
}

}  // namespace

TEST(TreeSolverAllocations, CounterSeesAllocations) {
  EXPECT_GT(allocationsIn([] { VecX x(100); x.setZero(); }), 0);
}

TEST(TreeSolverAllocations, NoneOnRandomTrees) {
  std::mt19937 rng(31);
  for (bool floating : {false, true}) {
    System s = randomSystem(30, floating, rng, RowRecipe{0.3, 0.3, 3});
    expectNoAllocation(s);
  }
}

TEST(TreeSolverAllocations, NoneWithLoopRows) {
  std::mt19937 rng(32);
  System s = randomSystem(12, true, rng, RowRecipe{0.2, 0.2, 1});
  Rows Ka(2, 6), Kb(2, 6);
  Ka.setRandom();
  Kb.setRandom();
  s.local.push_back(std::make_shared<LocalRows>("loop", 5, Ka, 9, Kb));
  s.joint.push_back(std::make_shared<JointRows>("joint", MatX::Random(1, s.model.nv)));
  makeConsistent(s, rng);
  expectNoAllocation(s);
}
