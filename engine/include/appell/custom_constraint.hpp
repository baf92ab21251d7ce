// User-supplied Pfaffian rows  A(q, t) v + b(q, t) = 0  over the generalized
// velocities, for constraints the library does not ship.
//
// The user gives, for m rows:
//   rows(model, q, t, A, b)            A: m × nv, b: m
//   bias(model, q, v, t, abias)        abias = Ȧ v + ḃ  (the acceleration-level
//                                      term: A v̇ + abias = 0 along motions)
// Optional per-row labels and holonomic flags (a holonomic row must be ġ for a
// gap g(q, t) = 0, given by `gap`, which the position projection then uses).
#pragma once

#include <appell/constraint.hpp>

#include <functional>
#include <vector>

namespace appell {

struct CustomRows {
  using RowsFn = std::function<void(const Model&, const VecX& q, double t, Eigen::Ref<MatX> A,
                                    Eigen::Ref<VecX> b)>;
  using BiasFn = std::function<void(const Model&, const VecX& q, const VecX& v, double t,
                                    Eigen::Ref<VecX> abias)>;
  using GapFn = std::function<void(const Model&, const VecX& q, double t, Eigen::Ref<VecX> gap)>;

  std::string name = "custom";
  int rows = 0;
  RowsFn A_b;
  BiasFn bias;
  GapFn gap;                        ///< optional; needed when any row is holonomic
  std::vector<std::string> labels;  ///< empty or one per row
  std::vector<bool> holonomic;      ///< empty (all nonholonomic) or one per row
  int body = -1;                    ///< body reported by bodyA() (−1: none in particular)
};

class CustomConstraint : public Constraint {
 public:
  /// Throws std::invalid_argument (naming the constraint) when rows ≤ 0, a
  /// callback is empty, labels/holonomic have the wrong length, or a holonomic
  /// row has no gap callback.
  explicit CustomConstraint(CustomRows spec);

  const std::string& name() const override { return spec_.name; }
  int rows() const override { return spec_.rows; }
  int bodyA() const override { return spec_.body; }
  /// Custom: the rows' meaning is the user's (their labels name it).
  RowKind rowKind(int) const override { return RowKind::Custom; }
  /// The user's label, or "custom<k>".
  std::string rowLabel(int k) const override;
  bool holonomic(int k) const override;
  bool jointSpace() const override { return true; }
  void reserve(const Model& model, RowBlock& block) const override;
  /// Calls the callbacks into the block's preallocated storage; a non-finite
  /// value is reported as singular (with the reason), not passed on silently.
  void evaluate(const Model& model, const Data& data, double t, const VecX& q, const VecX& v,
                RowBlock& out) const override;

 private:
  CustomRows spec_;
};

}  // namespace appell
