// The Whipple bicycle benchmark (examples/bicycle/bicycle.urdf) against the
// published eigenvalues: Meijaard, Papadopoulos, Ruina & Schwab (2007),
// "Linearized dynamics equations for the balance and steer of a bicycle: a
// benchmark and review", Proc. R. Soc. A 463:1955-1982, Table 2 (the four
// lean/steer eigenvalues at v = 0 ... 10 m/s, 14 decimals) and the weave and
// capsize speeds of their §5 (4.29238253634111 and 6.02426201538837 m/s).
//
// Upright straight running at speed v is a steady motion with x, y, heading
// and both wheel spins cyclic. The reduced linearization has dimension 5:
// lean, steer and their rates, and the forward speed. Running straight at
// any speed is steady, so the reference velocity v* (the family's tangent)
// is a null vector of L; the quotient by it, Uᵀ L U with U an orthonormal
// basis of its orthogonal complement, has exactly the other four
// eigenvalues: the paper's lean/steer spectrum.
//
// Accuracy: L is a central difference (LinearizationOptions::fd_step,
// default 1e-5), so the eigenvalues carry its O(h²) truncation and O(ε/h)
// round-off. The bounds below are a few times what was measured (comments),
// small enough to fail on any modelling error (measured with the CLI at 5 m/s:
// I_Bxz with the paper's z-down sign moves the weave pair by 0.8, a trail
// 1 mm longer moves it by 0.01).
#include <appell/appell.hpp>
#include <appell/linearization.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <string>
#include <vector>

using namespace appell;
using cd = std::complex<double>;

namespace {

const std::string kBicycle = std::string(APPELL_SOURCE_DIR) + "/examples/bicycle/bicycle.urdf";
constexpr double kRearRadius = 0.3, kFrontRadius = 0.35;  // Table 1: r_R, r_F
constexpr double kWeaveSpeed = 4.29238253634111;           // Meijaard et al. 2007, §5
constexpr double kCapsizeSpeed = 6.02426201538837;

// Table 2 of Meijaard et al. (2007): the eigenvalues at v = 0, 1, ..., 10 m/s
// (the weave pair as re ± i im).
struct Row {
  double v;
  std::vector<cd> eig;
};
std::vector<Row> table2() {
  auto pair = [](double re, double im) { return std::vector<cd>{cd(re, im), cd(re, -im)}; };
  auto row = [&](double v, double a, double re, double im, double d) {
    std::vector<cd> e = pair(re, im);
    e.push_back(a);
    e.push_back(d);
    return Row{v, e};
  };
  return {
      Row{0, {-3.13164324790656, 3.13164324790656, -5.53094371765393, 5.53094371765393}},
      row(1, -3.13423125066578, 3.52696170990070, 0.80774027519930, -7.11008014637442),
      row(2, -3.07158645641514, 2.68234517512745, 1.68066296590675, -8.67387984831735),
      row(3, -2.63366137253667, 1.70675605663975, 2.31582447384325, -10.35101467245920),
      row(4, -1.42944427361326, 0.41325331521125, 3.07910818603206, -12.15861426576450),
      row(5, -0.32286642900409, -0.77534188219585, 4.46486771378823, -14.07838969279820),
      row(6, -0.00406690076970, -1.52644486584142, 5.87673060598709, -16.08537123098030),
      row(7, 0.10268170574766, -2.13875644258362, 7.19525913329805, -18.15788466125262),
      row(8, 0.14327879765713, -2.69348683581097, 8.46037971396931, -20.27940894394569),
      row(9, 0.15790184030917, -3.21675402252485, 9.69377351531791, -22.43788559040858),
      row(10, 0.16105338653172, -3.72016840437287, 10.90681139476287, -24.62459635017404),
  };
}

struct Bicycle {
  Scene scene = loadScene(kBicycle);
  int plane_v = 0, rear_v = 0, front_v = 0;
  Bicycle() {
    plane_v = scene.model.joints[scene.model.jointIndex("plane")].idx_v;
    rear_v = scene.model.joints[scene.model.jointIndex("rear_spin")].idx_v;
    front_v = scene.model.joints[scene.model.jointIndex("front_spin")].idx_v;
  }
  // Upright, straight, forward speed v: the rear contact moves at v along the
  // heading, the wheels roll (ω = v/r), nothing else moves.
  VecX velocityAt(double v) const {
    VecX u = VecX::Zero(scene.model.nv);
    u[plane_v] = v;
    u[rear_v] = v / kRearRadius;
    u[front_v] = v / kFrontRadius;
    return u;
  }
};

struct LeanSteer {
  LinearizationResult lin;
  std::vector<cd> eig;    ///< the four lean/steer eigenvalues (the quotient by the speed)
  double null_residual;   ///< ‖L z₀‖ / ‖L‖ for the speed direction z₀
};

LeanSteer leanSteer(const Bicycle& b, double v, Formulation form = Formulation::Tree, double fd_step = 1e-5) {
  const Model& m = b.scene.model;
  LinearizationOptions lo;
  lo.fd_step = fd_step;
  lo.cyclic = {b.plane_v, b.plane_v + 1, b.plane_v + 2, b.rear_v, b.front_v};
  auto solver = makeSolver(form, m, b.scene.constraints);
  LeanSteer out;
  out.lin = linearize(m, b.scene.constraints, *solver, b.scene.q0, b.velocityAt(v), lo);
  const LinearizationResult& r = out.lin;
  // The speed direction in x_r = (θ retained, v), in the tangent basis.
  VecX x0 = VecX::Zero(r.basis.rows());
  x0.tail(m.nv) = b.velocityAt(1.0).normalized();
  const VecX z0 = r.basis.transpose() * x0;
  out.null_residual = (r.matrix * z0).norm() / r.matrix.norm();
  const MatX q = Eigen::HouseholderQR<MatX>(z0).householderQ();
  const MatX u = q.rightCols(r.dimension - 1);
  const Eigen::VectorXcd e = Eigen::EigenSolver<MatX>(u.transpose() * r.matrix * u).eigenvalues();
  out.eig.assign(e.data(), e.data() + e.size());
  return out;
}

// Largest error of `got` against `want`, each eigenvalue matched to its
// nearest, relative to max(1, |want|) (the capsize eigenvalue passes through 0).
double matchError(std::vector<cd> got, const std::vector<cd>& want) {
  double worst = 0;
  for (const cd& w : want) {
    auto it = std::min_element(got.begin(), got.end(), [&](cd a, cd b) { return std::abs(a - w) < std::abs(b - w); });
    worst = std::max(worst, std::abs(*it - w) / std::max(1.0, std::abs(w)));
    got.erase(it);
  }
  return worst;
}

double maxReal(const std::vector<cd>& e) {
  double r = -1e300;
  for (const cd& z : e) r = std::max(r, z.real());
  return r;
}

// Where the largest real part changes sign between lo and hi, by bisection.
double stabilityBoundary(const Bicycle& b, double lo, double hi) {
  const bool lo_unstable = maxReal(leanSteer(b, lo).eig) > 0;
  for (int it = 0; it < 60 && hi - lo > 1e-13; ++it) {
    const double mid = 0.5 * (lo + hi);
    ((maxReal(leanSteer(b, mid).eig) > 0) == lo_unstable ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

// The scene's own state (5 m/s) is a steady motion of dimension 5 with the
// speed as a null direction, and the four others are Table 2's.
TEST(BicycleBenchmark, SceneStateIsASteadyMotionWithTheSpeedAsNullDirection) {
  const Bicycle b;
  EXPECT_NEAR(b.scene.v0[b.plane_v], 5.0, 0);
  const LeanSteer ls = leanSteer(b, 5.0);
  EXPECT_EQ(ls.lin.dimension, 5);
  EXPECT_LT(ls.lin.constraint_residual, 1e-13);
  EXPECT_LT(ls.lin.steady_residual, 1e-12);
  EXPECT_LT(ls.lin.symmetry_residual, 1e-8);
  EXPECT_LT(ls.null_residual, 1e-9);
  EXPECT_LT(matchError(ls.eig, table2()[5].eig), 1e-8);
}

// Table 2 at every tabulated speed with the default finite-difference step.
// Measured (tree; -O1 and -O3 alike): worst 7.8e-9 relative to max(1, |μ|), at v = 9 m/s.
TEST(BicycleBenchmark, EigenvaluesMatchTable2AtEverySpeed) {
  const Bicycle b;
  double worst = 0;
  for (const Row& row : table2()) {
    const LeanSteer ls = leanSteer(b, row.v);
    const double err = matchError(ls.eig, row.eig);
    std::printf("v = %2.0f m/s: largest error %.2e (null residual %.1e)\n", row.v, err, ls.null_residual);
    EXPECT_LT(err, 1e-7) << "v = " << row.v;
    worst = std::max(worst, err);
  }
  std::printf("worst %.2e\n", worst);
}

// The three formulations give the same linearization (to the FD noise).
TEST(BicycleBenchmark, FormulationsAgreeOnTheSpectrum) {
  const Bicycle b;
  for (Formulation f : {Formulation::Multipliers, Formulation::Appell})
    EXPECT_LT(matchError(leanSteer(b, 3.0, f).eig, table2()[3].eig), 1e-7);
}

// Weave and capsize speeds: where the largest real part of the lean/steer
// spectrum changes sign. Measured: errors 2.0e-9 (weave) and 3.0e-8 (capsize)
// m/s — the capsize eigenvalue crosses zero with slope ≈ 0.17 s⁻¹ per m/s, so
// the finite-difference noise in μ is magnified about 6×.
TEST(BicycleBenchmark, WeaveAndCapsizeSpeeds) {
  const Bicycle b;
  const double weave = stabilityBoundary(b, 4.0, 5.0);
  const double capsize = stabilityBoundary(b, 6.0, 7.0);
  std::printf("weave %.15f (error %.1e), capsize %.15f (error %.1e)\n", weave, weave - kWeaveSpeed, capsize,
              capsize - kCapsizeSpeed);
  EXPECT_NEAR(weave, kWeaveSpeed, 1e-7);
  EXPECT_NEAR(capsize, kCapsizeSpeed, 2e-7);
}
