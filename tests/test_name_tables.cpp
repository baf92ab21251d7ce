// The closed sets of names — integrators, formulations, contact kinds, shapes —
// each have one table. These tests fail when a parser, an error message, the
// scene format, the command-line help or the docs drift from their table.
#include <appell/constrained_dynamics.hpp>
#include <appell/integrators.hpp>
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
