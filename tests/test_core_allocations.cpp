// No heap allocation inside the per-step algorithms.
//
// Every allocation in this executable is counted: the global operator new /
// delete are replaced, and so are malloc/calloc/realloc/aligned allocation —
// Eigen's dynamic matrices allocate through malloc, not through operator new,
// so counting only `new` would miss exactly the allocations that matter.
// (The replacements forward to glibc's __libc_* entry points.) Each algorithm
// is warmed up once (Data and the integrators are sized at construction), then
// called repeatedly while counting; the count must be zero. A positive control
// shows the counter sees both kinds of allocation.
#include "random_tree.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "alloc_counter.hpp"

using namespace appell;

namespace {

struct AbaField : AccelerationField {
  const Model& model;
  Data& data;
  const VecX& tau;
  AbaField(const Model& m, Data& d, const VecX& t) : model(m), data(d), tau(t) {}
  bool operator()(double, const VecX& q, const VecX& v, VecX& a) override {
    a = aba(model, data, q, v, tau);
    return true;
  }
};

class Allocations : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    std::mt19937 rng(GetParam() ? 5 : 6);
    model = test::randomTree(40, GetParam(), rng);
    data = std::make_unique<Data>(model);
    q = randomConfiguration(model, rng);
    v = test::randomVector(model.nv, rng);
    a = test::randomVector(model.nv, rng);
    tau = test::randomVector(model.nv, rng);
    fext.assign(model.nbodies, Vec6::Ones());
    J.resize(6, model.nv);
    theta = test::randomVector(model.nv, rng, 0.3);
    out_q.resize(model.nq);
    out_v.resize(model.nv);
  }
  Model model;
  std::unique_ptr<Data> data;
  VecX q, v, a, tau, theta, out_q, out_v;
  BodyForces fext;
  MatX J;
};

}  // namespace

TEST(AllocationCounter, SeesMallocAndNew) {
  const long n = allocationsIn([] {
    VecX x(1000);                      // Eigen: malloc
    auto p = std::make_unique<int>(3);  // operator new
    x.setConstant(*p);
    EXPECT_EQ(x.sum(), 3000.0);
  }, 5);
  EXPECT_EQ(n, 10);
}

TEST_P(Allocations, KinematicsDoNotAllocate) {
  Data& d = *data;
  EXPECT_EQ(allocationsIn([&] { forwardKinematics(model, d, q); }), 0);
  EXPECT_EQ(allocationsIn([&] { forwardKinematics(model, d, q, v); }), 0);
  EXPECT_EQ(allocationsIn([&] { forwardKinematics(model, d, q, v, a); }), 0);
  const int body = model.nbodies - 1;
  const Vec3 r(0.1, 0.2, 0.3);
  EXPECT_EQ(allocationsIn([&] { pointJacobian(model, d, body, r, J); }), 0);
  EXPECT_EQ(allocationsIn([&] { spatialJacobianWorld(model, d, body, J); }), 0);
  Vec6 sink = Vec6::Zero();
  EXPECT_EQ(allocationsIn([&] {
              sink += pointJacobianDotTimesV(d, body, r) + pointAcceleration(d, body, r) +
                      pointVelocity(d, body, r) + spatialVelocityWorld(d, body) +
                      spatialAccelerationWorld(d, body);
            }),
            0);
  EXPECT_TRUE(sink.allFinite());
}

TEST_P(Allocations, DynamicsDoNotAllocate) {
  Data& d = *data;
  EXPECT_EQ(allocationsIn([&] { rnea(model, d, q, v, a); }), 0);
  EXPECT_EQ(allocationsIn([&] { rnea(model, d, q, v, a, &fext); }), 0);
  EXPECT_EQ(allocationsIn([&] { nonLinearEffects(model, d, q, v); }), 0);
  EXPECT_EQ(allocationsIn([&] { crba(model, d, q); }), 0);
  EXPECT_EQ(allocationsIn([&] { aba(model, d, q, v, tau); }), 0);
  EXPECT_EQ(allocationsIn([&] { aba(model, d, q, v, tau, &fext); }), 0);
  double e = 0;
  EXPECT_EQ(allocationsIn([&] {
              e += kineticEnergy(model, d, q, v) + potentialEnergy(model, d, q) +
                   momentum(model, d, q, v).norm();
            }),
            0);
  EXPECT_TRUE(std::isfinite(e));
}

TEST_P(Allocations, ConfigurationManifoldDoesNotAllocate) {
  EXPECT_EQ(allocationsIn([&] { retract(model, q, theta, out_q); }), 0);
  EXPECT_EQ(allocationsIn([&] { localRate(model, q, theta, v, out_v); }), 0);
  EXPECT_EQ(allocationsIn([&] { retractWithRate(model, q, theta, v, out_q, out_v); }), 0);
  EXPECT_EQ(allocationsIn([&] { difference(model, q, out_q, out_v); }), 0);
  EXPECT_EQ(allocationsIn([&] { configurationRate(model, q, v, out_q); }), 0);
}

TEST_P(Allocations, IntegratorStepsDoNotAllocate) {
  for (IntegratorType type : {IntegratorType::SymplecticEuler, IntegratorType::RK4,
                              IntegratorType::DormandPrince54, IntegratorType::DormandPrince853}) {
    Data& d = *data;
    AbaField field(model, d, tau);
    auto integ = makeIntegrator(type, model);
    VecX qs = q, vs = v;
    double t = 0;
    double h = 1e-3;
    const long n = allocationsIn([&] {
      for (int k = 0; k < 2; ++k) {  // the second step reuses the FSAL stage
        const StepResult r = integ->step(field, t, qs, vs, h);
        ASSERT_TRUE(r.ok);
        if (integ->adaptive()) h = r.h_next;
        VecX& qd = out_q;
        VecX& vd = out_v;
        integ->denseOutput(0.5, qd, vd);  // DOP853: its three extra stages
      }
      integ->reset();  // and the next call takes the non-FSAL path
    });
    EXPECT_EQ(n, 0) << toString(type);
  }
}

INSTANTIATE_TEST_SUITE_P(Bases, Allocations, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return std::string(p.param ? "floating" : "fixed");
                         });
