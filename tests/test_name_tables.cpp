// The closed sets of names — integrators, formulations, contact kinds, shapes —
// each have one table. These tests fail when a parser, an error message, the
// scene format, the command-line help or the docs drift from their table.
#include <appell/constrained_dynamics.hpp>
#include <appell/configuration.hpp>
#include <appell/integrators.hpp>
#include <appell/joint_types.hpp>
#include <appell/urdf.hpp>

#include "test_contact_common.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <utility>

using namespace appell;

namespace {

// Every spelling of an entry, with hyphens and with underscores.
template <class Entry>
std::vector<std::string> spellings(const Entry& e) {
  std::vector<std::string> out;
  auto add = [&](std::string s) {
    out.push_back(s);
    for (char& c : s) c = c == '_' ? '-' : c;
    if (s != out.back()) out.push_back(s);
  };
  add(e.name);
  for (const char* a : e.aliases) add(a);
  return out;
}

template <class E, class Parse>
void expectTableParses(std::span<const NamedValue<E>> table, Parse parse, const char* what) {
  std::set<E> values;
  std::set<std::string> names;
  for (const NamedValue<E>& e : table) {
    EXPECT_TRUE(values.insert(e.value).second) << what << " " << e.name << " listed twice";
    EXPECT_STREQ(toString(e.value), e.name);
    EXPECT_NE(std::string(e.description), "") << e.name;
    for (const std::string& s : spellings(e)) {
      EXPECT_TRUE(names.insert(s).second) << "'" << s << "' names two " << what << "s";
      EXPECT_EQ(parse(s), e.value) << s;
    }
  }
  // An unknown name is refused with every accepted spelling in the message.
  try {
    parse("no-such-name");
    ADD_FAILURE() << "unknown " << what << " accepted";
  } catch (const std::invalid_argument& err) {
    const std::string msg = err.what();
    EXPECT_NE(msg.find(std::string("unknown ") + what + " 'no-such-name'"), std::string::npos) << msg;
    for (const NamedValue<E>& e : table) {
      EXPECT_NE(msg.find(e.name), std::string::npos) << msg;
      for (const char* a : e.aliases) EXPECT_NE(msg.find(a), std::string::npos) << msg;
    }
  }
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string kSceneFormat =
    readText(std::string(APPELL_SOURCE_DIR) + "/docs/scene-format.md");

// A body on a plane with one contact element (attributes given) and a
// <simulation> element (attributes given).
std::string scene(const std::string& contact, const std::string& simulation = "") {
  return R"(<?xml version="1.0"?>
<robot name="r">
  <link name="body">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <appell>
    <support name="ground" type="plane"/>
    <contact name="c" link="body" support="ground" )" +
         contact + R"(/>
    <simulation )" + simulation + R"(/>
  </appell>
</robot>)";
}

Scene load(const std::string& xml) {
  LoadOptions opt;
  opt.check_initial_state = false;
  return loadSceneFromString(xml, ".", "test.urdf", opt);
}

std::string loadError(const std::string& xml) {
  try {
    load(xml);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "loaded";
  return "";
}

const char* kDisk = R"(shape="disk" radius="0.1" axis="0 1 0")";

Model freeBody() {
  ModelBuilder b;
  b.addBody("b", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{1.0, Vec3::Zero(), Mat3::Identity()});
  return b.build();
}

}  // namespace

TEST(NameTables, IntegratorsParseEveryNameAndAlias) {
  expectTableParses(integratorTable(), integratorFromString, "integrator");
  const Model model = freeBody();
  for (const auto& e : integratorTable()) EXPECT_NE(makeIntegrator(e.value, model), nullptr) << e.name;
}

TEST(NameTables, FormulationsParseEveryNameAndAlias) {
  expectTableParses(formulationTable(), formulationFromString, "formulation");
  const Model model = freeBody();
  for (const auto& e : formulationTable()) {
    const auto solver = makeSolver(e.value, model, ConstraintList{});
    ASSERT_NE(solver, nullptr) << e.name;
    EXPECT_EQ(solver->formulation(), e.value) << e.name;
  }
}

TEST(NameTables, ContactKindsParseEveryNameAndAlias) {
  expectTableParses(contactKindTable(), contactKindFromString, "contact kind");
}

// The shape table has one entry per alternative of Shape, in the variant's order.
template <std::size_t... I>
void expectShapeEntriesInVariantOrder(std::index_sequence<I...>) {
  ASSERT_EQ(shapeTable().size(), sizeof...(I));
  const ShapeType* got[] = {&shapeType(Shape(std::in_place_index<I>))...};
  for (std::size_t k = 0; k < sizeof...(I); ++k) EXPECT_EQ(got[k], &shapeTable()[k]) << k;
}

TEST(NameTables, ShapeTableFollowsTheVariant) {
  expectShapeEntriesInVariantOrder(std::make_index_sequence<std::variant_size_v<Shape>>{});
  std::set<std::string> names;
  for (const ShapeType& t : shapeTable()) {
    for (const std::string& s : spellings(t)) {
      EXPECT_TRUE(names.insert(s).second) << "'" << s << "' names two shapes";
      EXPECT_EQ(findShapeType(s), &t) << s;
    }
    EXPECT_EQ(t.role == ShapeRole::Rolling, t.cannot_roll == nullptr) << t.name;
    EXPECT_EQ(t.make == nullptr, t.parameters.empty()) << t.name;
    EXPECT_EQ(t.make == nullptr, t.example == nullptr) << t.name;
  }
  EXPECT_EQ(findShapeType("no-such-shape"), nullptr);
}

// Every shape a contact can carry has a case in the contact tests' catalogue
// (their geometry, rows and physics run over it).
TEST(NameTables, EverySmoothShapeIsInTheContactTestCatalogue) {
  std::set<std::size_t> covered;
  for (const auto& c : appell::testing::shapeCases()) covered.insert(c.shape.index());
  for (std::size_t k = 0; k < shapeTable().size(); ++k)
    if (shapeTable()[k].role != ShapeRole::CollisionOnly) {
      EXPECT_TRUE(covered.count(k)) << shapeTable()[k].name << " has no case in shapeCases()";
    }
}

TEST(NameTables, SceneFileDeclaresEveryShapeByEveryName) {
  for (const ShapeType& t : shapeTable()) {
    if (!t.make) {
      // Collision-only shapes are named, with the reason, not "unknown".
      const std::string msg = loadError(scene(std::string("kind=\"sliding\" shape=\"") + t.name + "\""));
      EXPECT_NE(msg.find(t.cannot_roll), std::string::npos) << msg;
      continue;
    }
    for (const std::string& s : spellings(t)) {
      const Scene sc = load(scene("kind=\"sliding\" shape=\"" + s + "\" " + t.example));
      ASSERT_EQ(sc.contacts.size(), 1u);
      EXPECT_EQ(&shapeType(sc.contacts[0]->shape()), &t) << s;
    }
    // Each listed parameter is accepted; an unlisted one is refused.
    const std::string msg =
        loadError(scene("kind=\"sliding\" shape=\"" + std::string(t.name) + "\" " + t.example +
                        " bogus=\"1\""));
    EXPECT_NE(msg.find("attribute 'bogus' does not apply"), std::string::npos) << msg;
  }
  const std::string msg = loadError(scene(R"(kind="sliding" shape="blob")"));
  EXPECT_NE(msg.find("unknown shape 'blob'"), std::string::npos) << msg;
  for (const ShapeType& t : shapeTable()) {
    if (!t.make) continue;
    EXPECT_NE(msg.find(t.name), std::string::npos) << msg;
    for (const char* a : t.aliases) EXPECT_NE(msg.find(a), std::string::npos) << msg;
  }
}

TEST(NameTables, SceneFileAcceptsEveryContactKindSpelling) {
  for (const auto& e : contactKindTable())
    for (const std::string& s : spellings(e)) {
      const Scene sc = load(scene("kind=\"" + s + "\" " + kDisk));
      ASSERT_EQ(sc.contacts.size(), 1u);
      EXPECT_EQ(sc.contacts[0]->kind(), e.value) << s;
    }
  const std::string msg = loadError(scene(std::string(R"(kind="glue" )") + kDisk));
  for (const auto& e : contactKindTable()) EXPECT_NE(msg.find(e.name), std::string::npos) << msg;
}

TEST(NameTables, SimulationAcceptsEveryIntegratorAndFormulationSpelling) {
  for (const auto& e : formulationTable())
    for (const std::string& s : spellings(e))
      EXPECT_EQ(load(scene(kDisk, "formulation=\"" + s + "\"")).settings.formulation, e.name) << s;
  for (const auto& e : integratorTable())
    for (const std::string& s : spellings(e))
      EXPECT_EQ(load(scene(kDisk, "integrator=\"" + s + "\"")).settings.integrator, e.name) << s;
  // The alias the issue found refused.
  EXPECT_EQ(load(scene(kDisk, R"(formulation="multipliers")")).settings.formulation, "kkt");
  const std::string msg = loadError(scene(kDisk, R"(formulation="fast")"));
  for (const auto& e : formulationTable()) EXPECT_NE(msg.find(e.name), std::string::npos) << msg;
}

// docs/scene-format.md names every spelling of every table (as `name`).
TEST(NameTables, SceneFormatDocumentsEveryName) {
  auto documented = [](const std::string& name) {
    return kSceneFormat.find("`" + name + "`") != std::string::npos;
  };
  auto expectAll = [&](const auto& table) {
    for (const auto& e : table) {
      EXPECT_TRUE(documented(e.name)) << e.name << " missing from docs/scene-format.md";
      for (const char* a : e.aliases) EXPECT_TRUE(documented(a)) << a << " missing from docs/scene-format.md";
    }
  };
  expectAll(integratorTable());
  expectAll(formulationTable());
  expectAll(contactKindTable());
  for (const ShapeType& t : shapeTable()) {
    if (!t.make) continue;
    EXPECT_TRUE(documented(t.name)) << t.name << " missing from docs/scene-format.md";
    for (const char* a : t.aliases) EXPECT_TRUE(documented(a)) << a;
    for (const char* p : t.parameters) EXPECT_TRUE(documented(p)) << t.name << "." << p;
  }
}

// The joint type table (joint_types.hpp; its order and sizes are checked by a
// static_assert there): every entry names its type, and the model builder,
// the configuration space and the coordinate names do what it says — sizes,
// the quaternion's place (the neutral one is the identity, a zero one is
// found), positions that are local coordinates (a unit θ in the slot the
// table names moves exactly that position, and the position's name finds
// that slot).
TEST(NameTables, JointTypeTableDescribesEveryJointAsBuilt) {
  for (const JointTypeInfo& t : kJointTypes) {
    SCOPED_TRACE(t.name);
    EXPECT_STREQ(toString(t.type), t.name);
    EXPECT_EQ(findJointType(t.name), &t);
    EXPECT_EQ(jointNq(t.type), t.nq);
    EXPECT_EQ(jointNv(t.type), t.nv);
    ModelBuilder b;
    const Inertia box{1.0, Vec3::Zero(), Vec3(0.1, 0.2, 0.3).asDiagonal()};
    b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), box, "hinge");
    b.addBody("link", 0, SE3::Identity(), t.type, Vec3::UnitZ(), box, "j");
    const Model m = b.build();
    ASSERT_EQ(m.nq, 1 + t.nq);
    ASSERT_EQ(m.nv, 1 + t.nv);
    const std::vector<std::string> q_names = coordinateNames(m, false), v_names = coordinateNames(m, true);
    ASSERT_EQ(q_names.size(), static_cast<std::size_t>(m.nq));
    ASSERT_EQ(v_names.size(), static_cast<std::size_t>(m.nv));
    for (int k = 0; k < t.nv; ++k) EXPECT_EQ(localCoordinateIndex(m, v_names[1 + k]), 1 + k);
    const VecX q0 = neutralConfiguration(m);
    if (t.quaternion >= 0) {
      EXPECT_EQ(q0.segment<4>(1 + t.quaternion), Eigen::Vector4d(0, 0, 0, 1));
      VecX q = q0;
      q.segment<4>(1 + t.quaternion).setZero();
      EXPECT_EQ(degenerateQuaternionJoint(m, q), 1);
    }
    for (int k = 0; k < t.nq; ++k) {
      const bool in_quaternion = t.quaternion >= 0 && k >= t.quaternion && k < t.quaternion + 4;
      if (in_quaternion) {
        EXPECT_THROW(localCoordinateIndex(m, q_names[1 + k]), std::invalid_argument) << q_names[1 + k];
        continue;
      }
      ASSERT_GE(t.position_slot, 0);
      const int slot = 1 + t.position_slot + k;
      EXPECT_EQ(localCoordinateIndex(m, q_names[1 + k]), slot) << q_names[1 + k];
      VecX theta = VecX::Zero(m.nv), q(m.nq);
      theta[slot] = 0.25;
      retract(m, q0, theta, q);
      VecX moved = VecX::Zero(m.nq);
      moved[1 + k] = 0.25;
      EXPECT_EQ(q - q0, moved) << q_names[1 + k];
    }
  }
  EXPECT_EQ(findJointType("hinge"), nullptr);
}
