// No heap allocation inside Simulator::step(): every solver (KKT, Appell with
// both null spaces) with every integrator, on a system with holonomic and
// nonholonomic rows, a second body and a joint-force callback. The global
// operator new is replaced in this file and counts while armed.
#include <appell/appell_maggi.hpp>
#include <appell/contacts.hpp>
#include <appell/kkt.hpp>
#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/terrain.hpp>
#include <appell/urdf.hpp>

#include "scene.hpp"
#include "test_solver_rows.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>
#include <string>

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
}  // namespace

#if defined(APPELL_SANITIZED)
// Under a sanitizer, which owns malloc, its allocation hook counts instead.
#include <sanitizer/allocator_interface.h>
namespace {
void countingHook(const volatile void*, std::size_t) {
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
}
void ignoreFree(const volatile void*) {}
[[maybe_unused]] const int g_hooks_installed = __sanitizer_install_malloc_and_free_hooks(countingHook, ignoreFree);
}  // namespace
#else
// Eigen allocates with std::malloc (its aligned_malloc), the standard library
// with operator new, which ends in malloc too: interpose the C allocator
// itself (glibc exports the real one as __libc_*).
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

static void count() {
  if (g_armed.load(std::memory_order_relaxed)) {
    g_allocations.fetch_add(1);
    if (std::getenv("APPELL_ALLOC_TRAP")) __builtin_trap();
  }
}
void* malloc(std::size_t n) {
  count();
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) {
  count();
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) {
  count();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) {
  count();
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {
  count();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {
  count();
  *out = __libc_memalign(a, n);
  return *out ? 0 : 12;  // ENOMEM
}
void free(void* p) { __libc_free(p); }
}
#endif  // APPELL_SANITIZED

namespace appell {
namespace {

struct Arm {
  Arm() {
    g_allocations = 0;
    g_armed = true;
  }
  ~Arm() { g_armed = false; }
};

/// One step with the counter armed; its allocations added to `allocations`.
/// (The status is moved out after the counter is disarmed, as the tests
/// did inline.)
StepStatus armedStep(Simulator& sim, double h, long& allocations) {
  StepStatus st;
  {
    Arm arm;
    st = sim.step(h);
    allocations += g_allocations;
  }
  return st;
}

Model ballWithPendulum() {
  ModelBuilder b;
  b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{2.0, Vec3(0.01, -0.02, 0.03), Vec3(0.05, 0.06, 0.07).asDiagonal()}, "free");
  SE3 X;
  X.p = Vec3(0, 0, 0.1);
  b.addBody("bob", 0, X, JointType::Revolute, Vec3(1, 1, 0).normalized(),
            Inertia{0.5, Vec3(0, 0, -0.2), Vec3(0.01, 0.01, 0.002).asDiagonal()}, "hinge");
  return b.build();
}

TEST(SimulatorAllocation, StepDoesNotAllocate) {
  const Model model = ballWithPendulum();
  const double R = 0.3;
  // Rolling rows + a redundant copy of the no-slip rows (rank handling on the hot path).
  ConstraintList c{std::make_shared<test::RollingBall>("contact", 0, R),
                   std::make_shared<test::BodyRows>(
                       "extra", 0, std::vector<Vec6>{test::pointRow(Vec3(0, 0, 0.5), Vec3::UnitX())})};
  VecX q = neutralConfiguration(model);
  q[2] = R;
  VecX v = VecX::Zero(model.nv);
  v.head<3>() = Vec3(0.5, -1.0, 2.0);
  v.segment<3>(3) = Vec3(0.5, -1.0, 2.0).cross(Vec3(0, 0, R));
  v[6] = 1.0;
  for (int which = 0; which < 3; ++which) {
    for (IntegratorType it : {IntegratorType::SymplecticEuler, IntegratorType::Leapfrog,
                              IntegratorType::RK4, IntegratorType::DormandPrince54}) {
      std::unique_ptr<ConstrainedSolver> solver;
      if (which == 0) solver = std::make_unique<KktSolver>(model, c);
      if (which == 1) solver = std::make_unique<AppellSolver>(model, c);
      if (which == 2)
        solver = std::make_unique<AppellSolver>(model, c, SolverOptions{},
                                                AppellOptions{NullSpace::CoordinatePartition});
      Simulator sim(model, c, std::move(solver), it);
      sim.setJointForces([](double t, const VecX&, const VecX&, VecX& tau) {
        tau[6] = 0.1 * std::sin(t);  // a hinge motor
      });
      sim.setState(0, q, v);
      ASSERT_TRUE(sim.projectState().ok);
      long allocations = 0;
      for (int k = 0; k < 50; ++k) {
        const StepStatus st = armedStep(sim, 1e-3, allocations);
        ASSERT_TRUE(st.ok) << st.message;
      }
      EXPECT_EQ(allocations, 0) << "solver " << which << ", " << toString(it);
      EXPECT_LT(sim.velocityResidual(), 1e-10);
    }
  }
}

// The same with the contacts module's rolling rows on a four-wheeled car
// (a tree of five bodies, 12 rows of rank 9), rear-wheel drive.
TEST(SimulatorAllocation, CarWithContactRowsDoesNotAllocate) {
  ModelBuilder b;
  const int chassis = b.addBody("chassis", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                                Inertia{10, Vec3(0.1, 0, 0.1), Vec3(1, 2, 2.5).asDiagonal()});
  ConstraintList c;
  const double r = 0.3;
  for (int k = 0; k < 4; ++k) {
    SE3 X;
    X.p = Vec3(k < 2 ? 1.0 : -1.0, k % 2 ? -0.6 : 0.6, 0);
    const int w = b.addBody("wheel" + std::to_string(k), chassis, X, JointType::Continuous,
                            Vec3::UnitY(), Inertia{1, Vec3::Zero(), Vec3::Constant(0.036).asDiagonal()});
    c.push_back(makeContact(ContactKind::Rolling, w, Sphere{r, Vec3::Zero()},
                            Support{Plane{}, StaticMotion{}, "ground", -1}));
  }
  const Model model = b.build();
  VecX q = neutralConfiguration(model);
  q[2] = r;
  VecX v = VecX::Zero(model.nv);
  v[3] = 1.5;
  for (int k = 0; k < 4; ++k) v[6 + k] = 1.5 / r;
  for (int which = 0; which < 3; ++which) {
    std::unique_ptr<ConstrainedSolver> solver;
    if (which == 0) solver = std::make_unique<KktSolver>(model, c);
    if (which == 1) solver = std::make_unique<AppellSolver>(model, c);
    if (which == 2)
      solver = std::make_unique<AppellSolver>(model, c, SolverOptions{},
                                              AppellOptions{NullSpace::CoordinatePartition});
    Simulator sim(model, c, std::move(solver), IntegratorType::DormandPrince54);
    sim.setJointForces([](double, const VecX&, const VecX&, VecX& tau) {
      tau[8] = tau[9] = 0.3;
    });
    sim.setState(0, q, v);
    long allocations = 0;
    for (int k = 0; k < 30; ++k) {
      const StepStatus st = armedStep(sim, 1e-2, allocations);
      ASSERT_TRUE(st.ok) << st.message;
    }
    EXPECT_EQ(allocations, 0) << "solver " << which;
    EXPECT_EQ(sim.redundantRows(), 3);
  }
}

// A uniform ball (radius 0.1 m, 0.5 kg) on a free joint and its contact with
// the plane z = 0: `spec`'s friction and restitution, rolling on a sphere.
constexpr double kBallRadius = 0.1, kBallMass = 0.5;
struct BallOnPlane {
  Model model;
  ConstraintList constraints;
};
BallOnPlane ballOnPlane(ContactSpec spec) {
  ModelBuilder b;
  const double I = 0.4 * kBallMass * kBallRadius * kBallRadius;
  const int ball = b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             Inertia{kBallMass, Vec3::Zero(), Vec3::Constant(I).asDiagonal()});
  BallOnPlane s;
  s.model = b.build();
  spec.kind = ContactKind::Rolling;
  spec.body = ball;
  spec.shape = Sphere{kBallRadius, Vec3::Zero()};
  spec.support = Support{Plane{}, StaticMotion{}, "ground", -1};
  s.constraints = {makeContact(spec)};
  return s;
}

// The three formulations by number: 0 KKT, 1 Appell/Maggi, 2 tree.
std::unique_ptr<ConstrainedSolver> solverNumber(int which, const Model& model,
                                                const ConstraintList& c) {
  if (which == 0) return std::make_unique<KktSolver>(model, c);
  if (which == 1) return std::make_unique<AppellSolver>(model, c);
  return makeSolver(Formulation::Tree, model, c);
}

// The ball with friction μ on the plane, launched sliding at 1 m/s without
// spin (it sticks at t = 2v₀/(7μg)), and pushed along x by F = k (t − 0.2 s)
// from 0.2 s: it slips again when (2/7)F reaches μmg, near
// 0.2 + 3.5 μmg/k. Shared by the friction tests of the two schemes.
constexpr double kPushStart = 0.2, kPushRate = 20.0;
struct PushedBall {
  BallOnPlane s;
  VecX q, v;
};
PushedBall pushedBall(double mu) {
  ContactSpec spec;
  spec.mu = mu;
  PushedBall b{ballOnPlane(spec), {}, {}};
  b.q = neutralConfiguration(b.s.model);
  b.q[2] = kBallRadius;
  b.v = VecX::Zero(b.s.model.nv);
  b.v[3] = 1.0;
  return b;
}
void push(Simulator& sim) {
  sim.setJointForces([](double t, const VecX& qq, const VecX&, VecX& tau) {
    const double F = t > kPushStart ? kPushRate * (t - kPushStart) : 0.0;
    tau.tail<3>() = scenes::floatingRotation(qq, 0).transpose() * Vec3(F, 0, 0);
  });
}

// Steps that hold contact events (touchdown, impacts, the active set
// changing, bounces) allocate nothing either: every row has its storage from
// the start and the event list is reserved. A ball with restitution 0.5
// dropped 0.2 m: 9 bounces and a plastic touchdown in 1.5 s, each solver,
// dopri5 and dop853 (dense-output location; dop853's three extra stages)
// and RK4 (shortened steps). With μ = 0.005 its later impacts slide
// (friction_impact.cpp); with μ = 0.3 and a creep speed its friction is the
// regularized law, superposed at every stage: none of that allocates.
TEST(SimulatorAllocation, ContactEventsDoNotAllocate) {
 for (const auto& [mu, creep] : {std::pair{std::numeric_limits<double>::infinity(), 0.0},
                                 std::pair{0.005, 0.0}, std::pair{0.3, 0.05}}) {
  const double r = kBallRadius;
  ContactSpec spec;
  spec.restitution = 0.5;
  spec.mu = mu;
  spec.creep_speed = creep;
  const BallOnPlane s = ballOnPlane(spec);
  const Model& model = s.model;
  const ConstraintList& c = s.constraints;
  VecX q = neutralConfiguration(model);
  q[2] = r + 0.2;
  VecX v = VecX::Zero(model.nv);
  v.head<3>() = Vec3(0, 4.0, 1.0);  // spinning: the impacts are rolling impacts
  v[3] = 0.3;
  for (int which = 0; which < 3; ++which) {
    for (IntegratorType it : {IntegratorType::Leapfrog, IntegratorType::RK4,
                              IntegratorType::DormandPrince54, IntegratorType::DormandPrince853}) {
      std::unique_ptr<ConstrainedSolver> solver = solverNumber(which, model, c);
      SimulatorOptions so;
      so.contacts.rest_speed = 0.01;
      Simulator sim(model, c, std::move(solver), it, {}, so);
      ASSERT_TRUE(sim.setState(0, q, v));
      long allocations = 0, events = 0, slips = 0;
      while (sim.time() < 1.5) {
        const StepStatus st = armedStep(sim, 2e-3, allocations);
        ASSERT_TRUE(st.ok) << st.message;
        events += st.events;
        for (const ContactEvent& e : sim.events()) slips += e.kind == ContactEventKind::Slip;
      }
      const std::string what = "solver " + std::to_string(which) + ", " + toString(it) + ", μ = " + std::to_string(mu);
      EXPECT_GE(events, 8) << what;
      if (std::isfinite(mu) && creep == 0) {
        EXPECT_GE(slips, 1) << what << ": a sliding impact";
      }
      if (creep > 0) {
        EXPECT_EQ(slips, 0) << what << ": a creeping contact never sticks or slips";
      }
      EXPECT_EQ(allocations, 0) << what;
      EXPECT_TRUE(sim.isClosed(0));
    }
  }
 }
}

// Friction events allocate nothing: a ball launched sliding sticks (the
// stick event, decided by the onset problem), then a push F = kt along x
// makes it slip again (the slip event at its cone: the onset problem with
// that contact forced) and slides on, its first instants on the settled
// direction — every workspace sized when the simulator is built.
TEST(SimulatorAllocation, FrictionEventsDoNotAllocate) {
  const double mu = 0.3;
  const PushedBall b = pushedBall(mu);  // sticks at t ≈ 0.097 s, pushed from 0.2 s
  const Model& model = b.s.model;
  const ConstraintList& c = b.s.constraints;
  for (int which = 0; which < 3; ++which) {
    for (IntegratorType it : {IntegratorType::Leapfrog, IntegratorType::RK4,
                              IntegratorType::DormandPrince54}) {
      std::unique_ptr<ConstrainedSolver> solver = solverNumber(which, model, c);
      Simulator sim(model, c, std::move(solver), it);
      push(sim);
      ASSERT_TRUE(sim.setState(0, b.q, b.v));
      long allocations = 0, slips = 0, sticks = 0;
      const double t_end = kPushStart + 3.5 * mu * kBallMass * 9.81 / kPushRate + 0.1;
      // 0.1 s past the slip: the slip's first instants slide on the settled
      // direction (friction_settled.cpp), whose solves allocate nothing either.
      while (sim.time() < t_end) {
        const StepStatus st = armedStep(sim, 2e-3, allocations);
        ASSERT_TRUE(st.ok) << st.message;
        for (const auto& e : sim.events()) {
          slips += e.kind == ContactEventKind::Slip;
          sticks += e.kind == ContactEventKind::Stick;
        }
      }
      EXPECT_EQ(sticks, 1) << "solver " << which << ", " << toString(it);
      EXPECT_GE(slips, 1) << "solver " << which << ", " << toString(it);
      EXPECT_EQ(allocations, 0) << "solver " << which << ", " << toString(it);
    }
  }
}

// A time-stepping step (timestepping/moreau_jean.cpp: the free motion, the
// Delassus operator — here from the mass matrix, no row being closed —, the
// Gauss–Seidel contact problem and its finish) allocates nothing either: its
// buffers are sized when the stage is built. A ball launched sliding at 1 m/s sticks after
// 2v₀/(7μg) ≈ 0.097 s and is pushed from 0.2 s until it slips again — every
// mode a contact takes in a window (slide, stick, slide), in each solver.
TEST(SimulatorAllocation, TimeSteppingStepsDoNotAllocate) {
  const double mu = 0.3;
  const PushedBall b = pushedBall(mu);
  const Model& model = b.s.model;
  const ConstraintList& c = b.s.constraints;
  SimulatorOptions so;
  so.scheme = ContactScheme::TimeStepping;
  for (int which = 0; which < 3; ++which) {
    Simulator sim(model, c, solverNumber(which, model, c), IntegratorType::RK4, {}, so);
    push(sim);
    ASSERT_TRUE(sim.setState(0, b.q, b.v));
    long allocations = 0, sliding_steps = 0, sticking_steps = 0;
    const double t_end = kPushStart + 3.5 * mu * kBallMass * 9.81 / kPushRate + 0.1;
    while (sim.time() < t_end) {
      const StepStatus st = armedStep(sim, 1e-3, allocations);
      ASSERT_TRUE(st.ok) << st.message;
      // (Closed but for the odd step: a spinning body's explicit step lifts
      // it by O(h² ω² |v|) — micrometres here — and it lands again.)
      if (sim.isClosed(0)) (sim.constraintData().isSliding(0) ? sliding_steps : sticking_steps) += 1;
    }
    EXPECT_EQ(sim.counters().timestepping_steps, sim.counters().steps);
    EXPECT_GT(sliding_steps, 100) << "solver " << which;
    EXPECT_GT(sticking_steps, 100) << "solver " << which;
    EXPECT_EQ(allocations, 0) << "solver " << which;
  }
}

// The other Delassus path, one solve of the scene's solver per row, where
// rows stay closed for the step (timestepping/delassus.cpp): the steered car
// (examples/steered_car), whose knuckles follow its hand wheel through two
// mimic couplings — bilateral rows — time-stepped with its servos for 0.3 s
// on its four tyres, allocates nothing either.
TEST(SimulatorAllocation, TimeSteppingWithBilateralRowsDoesNotAllocate) {
  const Scene s = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/steered_car/steered_car.urdf");
  RunOptions o = runOptions(s.settings);
  o.contacts = ContactScheme::TimeStepping;
  const auto sim = makeSimulator(s, o);
  ASSERT_GT(sim->constraintData().m_active, 0) << "the mimic rows are closed";
  long allocations = 0, closed_steps = 0;
  while (sim->time() < 0.3) {
    const StepStatus st = armedStep(*sim, 1e-3, allocations);
    ASSERT_TRUE(st.ok) << st.message;
    int closed = 0;
    for (int c = 0; c < static_cast<int>(sim->constraints().size()); ++c) {
      const std::string& name = sim->constraints()[c]->name();
      closed += (name == "fl" || name == "fr" || name == "rl" || name == "rr") && sim->isClosed(c);
    }
    closed_steps += closed == 4;
  }
  EXPECT_EQ(sim->counters().timestepping_steps, sim->counters().steps);
  EXPECT_GT(closed_steps, 250) << "on its four tyres";
  EXPECT_EQ(allocations, 0);
}

// Servos in time-stepping (timestepping/implicit_servos.cpp) allocate
// nothing either: a ball on a vertical slider dropped onto the floor, its
// stiff servo (implicit: (ω h)² = 1) pressing it down past its effort limit
// and then lifting it — the servo alone in flight, with the contact after
// touchdown, at and off its limit, and the gate every 100 steps.
TEST(SimulatorAllocation, TimeSteppingServosDoNotAllocate) {
  const Scene s = loadSceneFromString(R"(<robot name="press"><link name="world"/>
<link name="ball"><inertial><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
<collision><geometry><sphere radius="0.05"/></geometry></collision></link>
<joint name="z" type="prismatic"><parent link="world"/><child link="ball"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="30" velocity="100"/></joint>
<appell>
  <support name="floor" type="plane" normal="0 0 1" offset="0"/>
  <contact name="foot" link="ball" kind="sliding" support="floor"/>
  <initial><joint name="z" position="0.08"/></initial>
  <actuator name="press" joint="z" type="position" kp="1000000" kv="20">
    <setpoint t="0" value="0.04"/><setpoint t="0.3" value="0.04"/><setpoint t="0.31" value="0.2"/>
  </actuator>
</appell></robot>)",
                                      ".", "press.urdf");
  RunOptions o;
  o.contacts = ContactScheme::TimeStepping;
  const auto sim = makeSimulator(s, o);
  long allocations = 0, closed_steps = 0;
  while (sim->time() < 0.5) {
    const StepStatus st = armedStep(*sim, 1e-3, allocations);
    ASSERT_TRUE(st.ok) << st.message;
    closed_steps += sim->isClosed(0);
  }
  EXPECT_GT(closed_steps, 100);
  EXPECT_LT(closed_steps, 450) << "lifted off when the set-point rose";
  EXPECT_EQ(allocations, 0);
}

// Changes of terrain piece allocate nothing (contact_features.cpp): a ball
// rolling at 0.5 m/s over a convex crease onto a ramp of slope 1/4 moves onto
// the edge, pivots, and moves onto the ramp's face — two located events — in
// each solver, with dense-output location (dopri5) and shortened steps.
TEST(SimulatorAllocation, TerrainFeatureEventsDoNotAllocate) {
  ContactSpec spec;
  BallOnPlane s = ballOnPlane(spec);
  spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
  spec.support = Support{makeTerrain({Vec3(-4, 0, 0), Vec3(0, -3, 0), Vec3(0, 3, 0), Vec3(3, 0, -0.75)},
                                     {{0, 1, 2}, {1, 3, 2}}),
                         StaticMotion{}, "crease", -1};
  s.constraints = {makeContact(spec)};
  VecX q = neutralConfiguration(s.model);
  q.head<3>() = Vec3(-0.2, 0.1, kBallRadius);
  VecX v = VecX::Zero(s.model.nv);
  v[1] = 0.5 / kBallRadius;  // rolling along +x
  v[3] = 0.5;
  for (int which = 0; which < 3; ++which) {
    for (IntegratorType it : {IntegratorType::Leapfrog, IntegratorType::RK4,
                              IntegratorType::DormandPrince54}) {
      Simulator sim(s.model, s.constraints, solverNumber(which, s.model, s.constraints), it);
      ASSERT_TRUE(sim.setState(0, q, v));
      long allocations = 0, pieces = 0;
      while (sim.time() < 1.0) {
        const StepStatus st = armedStep(sim, 2e-3, allocations);
        ASSERT_TRUE(st.ok) << st.message;
        for (const ContactEvent& e : sim.events()) pieces += e.kind == ContactEventKind::Feature;
      }
      EXPECT_EQ(pieces, 2) << "solver " << which << ", " << toString(it);
      EXPECT_EQ(allocations, 0) << "solver " << which << ", " << toString(it);
      EXPECT_TRUE(sim.isClosed(0));
    }
  }
}

// Two points of one pair (ContactSpec::points): a frictionless ball dropped
// into a V takes turns touching down on the two slopes (the watcher's
// search past the held piece, the handover at each crossing of the bottom)
// and comes to rest on both — no allocation in any solver or integrator.
TEST(SimulatorAllocation, SecondPointTouchdownsDoNotAllocate) {
  ContactSpec spec;
  BallOnPlane s = ballOnPlane(spec);
  spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
  const double h = 2 * std::tan(M_PI / 6);
  spec.support = Support{makeTerrain({{-2, -2, h}, {0, -2, 0}, {0, 2, 0}, {-2, 2, h}, {2, -2, h}, {2, 2, h}},
                                     {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}}),
                         StaticMotion{}, "valley", -1};
  spec.kind = ContactKind::Sliding;
  spec.points = 2;
  s.constraints.clear();
  for (auto& c : makeContactPoints(spec)) s.constraints.push_back(c);
  VecX q = neutralConfiguration(s.model);
  q.head<3>() = Vec3(-0.3, 0, 0.8);
  const VecX v = VecX::Zero(s.model.nv);
  for (int which = 0; which < 3; ++which) {
    for (IntegratorType it : {IntegratorType::Leapfrog, IntegratorType::RK4,
                              IntegratorType::DormandPrince54}) {
      Simulator sim(s.model, s.constraints, solverNumber(which, s.model, s.constraints), it);
      ASSERT_TRUE(sim.setState(0, q, v));
      long allocations = 0, second = 0;
      while (sim.time() < 2.0) {
        const StepStatus st = armedStep(sim, 2e-3, allocations);
        ASSERT_TRUE(st.ok) << st.message;
        for (const ContactEvent& e : sim.events())
          second += e.kind == ContactEventKind::Touchdown && e.constraint == 1;
      }
      EXPECT_GE(second, 3) << "solver " << which << ", " << toString(it);
      EXPECT_EQ(allocations, 0) << "solver " << which << ", " << toString(it);
      EXPECT_TRUE(sim.isClosed(0) && sim.isClosed(1)) << "at rest on both slopes";
    }
  }
}

// The counter works: a step that fails (and builds its message) does allocate.
TEST(SimulatorAllocation, CounterSeesAllocations) {
  Arm arm;
  auto p = std::make_unique<std::vector<double>>(100);
  EXPECT_GT(g_allocations.load(), 0);
}

}  // namespace
}  // namespace appell
