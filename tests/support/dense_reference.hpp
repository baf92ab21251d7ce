// Dense references the tree-solver tests check against: Udwadia–Kalaba
// (Udwadia & Kalaba, Proc. R. Soc. Lond. A 439, 1992) in long double, and the
// dense M-metric velocity projection. Their own library (appell_test_reference):
// the SVDs and eigensolvers in two scalar types are the slowest file of the
// tests to compile, so only the tests that include this header build and link it.
#pragma once

#include <appell/appell.hpp>

namespace appell::test {

/// Pseudo-inverse solve with a relative singular-value threshold.
VecX pinvSolve(const MatX& A, const VecX& b, double rel = 1e-10);

struct Reference {
  VecX vdot, lambda, reaction;
  int rank = 0;
};

/// Udwadia–Kalaba with the symmetric square root of M, evaluated in long
/// double so that the reference is not the least accurate party (the tree
/// solver is often more accurate than the same formula in double).
Reference denseReference(const Model& model, const ConstraintData& cd, const VecX& q,
                         const VecX& v, const VecX& tau);

/// Dense M-metric projection v⁺ = v + M^{-½}(A M^{-½})⁺(−b − A v).
VecX denseProjection(const Model& model, const ConstraintData& cd, const VecX& q,
                     const VecX& v);

}  // namespace appell::test
