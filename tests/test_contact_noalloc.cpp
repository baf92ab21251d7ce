// Contact evaluation allocates nothing: every kind, shape and support (the
// ellipsoid's Newton solves included), regular and singular states.
#include "test_contact_common.hpp"

#include <appell/appell.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

// Every allocation is counted: operator new and malloc and friends (Eigen's
// dynamic matrices allocate through malloc), forwarding to glibc's __libc_*.
#include "alloc_counter.hpp"

using namespace appell;
using namespace appell::testing;

TEST(ContactNoAlloc, CounterSeesAllocations) {
  g_allocations = 0;
  g_counting = true;
  auto* p = new std::vector<double>(100);
  g_counting = false;
  delete p;
  EXPECT_GE(g_allocations.load(), 2);
  g_allocations = 0;
  g_counting = true;
  {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(50);  // Eigen allocates through malloc
    EXPECT_EQ(x.size(), 50);
  }
  g_counting = false;
  EXPECT_GE(g_allocations.load(), 1);
}

TEST(ContactNoAlloc, EvaluateDoesNotAllocate) {
  ModelBuilder b;
  b.addBody("body", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{1.0, Vec3::Zero(), Mat3::Identity() * 0.1});
  const Model model = b.build();
  Data data(model);
  std::mt19937 rng(8);
  int evaluations = 0;
  for (const auto& shc : shapeCases()) {
    for (const auto& suc : supportCases()) {
      std::vector<ContactKind> kinds{ContactKind::Sliding};
      if (canRoll(shc.shape)) {
        kinds.push_back(ContactKind::Rolling);
        kinds.push_back(ContactKind::RollingWithoutSpin);
      }
      if (hasBlade(shc.shape)) kinds.push_back(ContactKind::KnifeEdge);
      for (ContactKind kind : kinds) {
        ContactOptions o;
        if (kind == ContactKind::KnifeEdge && std::holds_alternative<PointShape>(shc.shape))
          o.blade_direction = Vec3(1, 0.2, 0.1);
        const auto c = makeContact(kind, 0, shc.shape, suc.support, o);
        RowBlock blk;
        c->reserve(model, blk);
        SE3 pose;
        ASSERT_TRUE(placeNearContact(shc.shape, suc.support.surface,
                                     supportState(suc.support.motion, 0.3), rng, 0.01, pose));
        const Quat r(pose.R);
        VecX q(7), v(6);
        q << pose.p, r.x(), r.y(), r.z(), r.w();
        v << randomVec(rng), randomVec(rng);
        forwardKinematics(model, data, q, v);
        // Also a singular state: the support centre at the body (bowls), flat wheels …
        SE3 odd;
        odd.p = Vec3(0.1, 0.3, 2.0);
        g_allocations = 0;
        g_counting = true;
        c->evaluate(model, data, 0.3, q, v, blk);
        c->evaluateAt(odd, Vec6::Ones(), 0.3, blk);
        c->evaluateAt(pose, Vec6::Ones(), 0.3, blk);
        g_counting = false;
        EXPECT_EQ(g_allocations.load(), 0) << toString(kind) << " " << shc.name << " on "
                                           << suc.name;
        evaluations += 3;
      }
    }
  }
  EXPECT_GT(evaluations, 300);
}
