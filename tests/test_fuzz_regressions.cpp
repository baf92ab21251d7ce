// Inputs the fuzzers found (scripts/fuzz.sh) and the reproducers of issues
// filed against the loader, kept in tests/data/fuzz-regressions: each must be
// refused or loaded cleanly — never a crash, and under the sanitizer build
// (scripts/sanitize.sh) never a memory error. Meshes (assimp_*, mesh_*,
// whatever their suffix: the mesh gate sniffs the format from the content)
// go through loadMesh, everything else through the scene loader. Files
// named …_oom… made a library allocate gigabytes, and …_refused… crashed or
// aborted inside it: both must be refused before it reads them.
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace appell;

TEST(FuzzRegressions, EveryFindingIsRefusedOrLoadedCleanly) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(APPELL_SOURCE_DIR) / "tests/data/fuzz-regressions";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path p = entry.path();
    ++files;
    // A finding that made a library allocate gigabytes (…_oom.…) must be
    // refused before the library reads it.
    const std::string name = p.filename().string();
    const bool must_refuse =
        name.find("_oom") != std::string::npos || name.find("_refused") != std::string::npos;
    try {
      if (name.rfind("assimp_", 0) == 0 || name.rfind("mesh_", 0) == 0) {
        const TriangleMesh m = loadMesh(p.string());
        EXPECT_FALSE(must_refuse) << p << " was loaded";
        for (const auto& t : m.triangles)
          for (int v : t) ASSERT_LT(static_cast<std::size_t>(v), m.vertices.size()) << p;
      } else {
        std::ifstream in(p, std::ios::binary);
        const std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        (void)loadSceneFromString(xml, dir.string(), p.filename().string());
      }
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos)
          << "the error names the file: " << e.what();
    }
  }
  EXPECT_GE(files, 1);
}

// The Collada damage the mesh fuzzer found, made from the example wheel: a
// stray byte or a coordinate inside an index list, and a count no file of
// this size could hold — each refused with the file, the line and the
// element before assimp reads it (assimp 5.2.5 allocates gigabytes for them).
TEST(FuzzRegressions, DamagedColladaNumberListsAreRefusedBeforeAssimpReadsThem) {
  namespace fs = std::filesystem;
  std::ifstream in(fs::path(APPELL_SOURCE_DIR) / "examples/diff_drive/meshes/wheel.dae", std::ios::binary);
  const std::string wheel((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string p = wheel.substr(wheel.find("<p>"), 40);
  auto refused = [&](const std::string& from, const std::string& to, const std::string& what) {
    std::string dae = wheel;
    const auto at = dae.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    dae.replace(at, from.size(), to);
    const fs::path path = fs::path(::testing::TempDir()) / "damaged_wheel.dae";
    std::ofstream(path, std::ios::binary) << dae;
    try {
      loadMesh(path.string());
      ADD_FAILURE() << "loaded: " << what;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("damaged_wheel.dae:"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(p, p.substr(0, 10) + "\xe0\xc5" + p.substr(12), "<p>: an index list holds 0xe0");
  refused(p, "<p>0.0839018 -0.017" + p.substr(19), "<p>: an index list holds '.'");
  refused(p, p.substr(0, 10) + "\f" + p.substr(11), "<p>: an index list holds 0x0c");
  refused(p, "<p>98765432109876 " + p.substr(3), "<p>: an index or count larger than the file could hold");
  refused("count=\"3270\"", "count=\"3270000000\"", "more values than the file could hold");
  refused("0.0796148", "0.07x6148", "<float_array>: a number list holds 'x'");
  refused("array\" count=\"3270\"", "array\" mater=\"3270\"", "<float_array>: has no count attribute");
  // The undamaged file loads.
  EXPECT_EQ(loadMesh((fs::path(APPELL_SOURCE_DIR) / "examples/diff_drive/meshes/wheel.dae").string()).triangles.size(), 2176u);
}

namespace {

std::string meshError(const std::string& text, const std::string& file) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / file;
  std::ofstream(path, std::ios::binary) << text;
  try {
    const TriangleMesh m = loadMesh(path.string());
    return "(loaded " + std::to_string(m.triangles.size()) + " triangles)";
  } catch (const SceneError& e) {
    return e.what();
  }
}

const char* kTriangleGeometry =
    "<library_geometries><geometry id=\"tri\"><mesh>"
    "<source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>"
    "<technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
    "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
    "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>"
    "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1 2</p></triangles>"
    "</mesh></geometry></library_geometries>";

// A Collada file whose visual scene holds `scene_nodes` and whose library
// holds `library_nodes`.
std::string collada(const std::string& scene_nodes, const std::string& library_nodes = "") {
  return std::string("<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" "
                     "version=\"1.4.1\">") +
         kTriangleGeometry + "<library_nodes>" + library_nodes +
         "</library_nodes><library_visual_scenes><visual_scene id=\"S\">" + scene_nodes +
         "</visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#S\"/></scene></COLLADA>\n";
}

}  // namespace

// Issue 41, reproducers 2–4: assimp recursed for ever on an <instance_node>
// naming its own node (a segfault, even for a visual mesh), overflowed its
// stack on node trees 8 000 deep (Collada) or 20 000 deep (glTF), and the
// Collada checks ran only for "*.dae" names while assimp recognises Collada
// by content. Each is now refused by the mesh gate, whatever the file's name.
TEST(FuzzRegressions, ColladaNodeGraphsAreBoundedBeforeAssimpBuildsThem) {
  const std::string node = "<node id=\"t\"><instance_geometry url=\"#tri\"/></node>";
  EXPECT_EQ(meshError(collada(node), "plain.xml"), "(loaded 1 triangles)");
  // A cycle through a nested node, under any name.
  const std::string loop = "<node id=\"loop\"><node id=\"in\"><instance_node url=\"#loop\"/></node></node>";
  for (const char* file : {"loop.dae", "loop.xml", "loop.zae", "loop"}) {
    const std::string m = meshError(collada("<node id=\"r\"><instance_node url=\"#loop\"/></node>", loop), file);
    EXPECT_NE(m.find(std::string(file) + ":2: <node id=\"loop\">: instances itself"), std::string::npos) << m;
  }
  // 8 000 nested nodes.
  std::string deep;
  for (int i = 0; i < 8000; ++i) deep += "<node>";
  deep += "<instance_geometry url=\"#tri\"/>";
  for (int i = 0; i < 8000; ++i) deep += "</node>";
  EXPECT_NE(meshError(collada(deep), "deep.dae").find(">: elements nested more than 256 deep"), std::string::npos)
      << meshError(collada(deep), "deep.dae").substr(0, 300);
  // A chain of 300 library nodes, each instancing the next: shallow XML, a
  // 300-level tree once expanded.
  std::string chain;
  for (int k = 0; k < 300; ++k)
    chain += "<node id=\"c" + std::to_string(k) + "\"><instance_node url=\"#c" + std::to_string(k + 1) + "\"/></node>";
  chain += "<node id=\"c300\"><instance_geometry url=\"#tri\"/></node>";
  const std::string m_chain = meshError(collada("<node id=\"r\"><instance_node url=\"#c0\"/></node>", chain), "chain.dae");
  EXPECT_NE(m_chain.find("levels deep once its <instance_node>s are expanded (at most 256)"), std::string::npos) << m_chain;
  // 2²⁴ instances from 24 nodes each instancing the previous one twice.
  std::string bomb = "<node id=\"n0\"><instance_geometry url=\"#tri\"/></node>";
  for (int k = 1; k <= 24; ++k)
    bomb += "<node id=\"n" + std::to_string(k) + "\"><instance_node url=\"#n" + std::to_string(k - 1) +
            "\"/><instance_node url=\"#n" + std::to_string(k - 1) + "\"/></node>";
  const std::string m_bomb = meshError(collada("<node id=\"r\"><instance_node url=\"#n24\"/></node>", bomb), "bomb.dae");
  EXPECT_NE(m_bomb.find("expands to more than 100000 nodes through its <instance_node>s"), std::string::npos) << m_bomb;
  // A DAG that shares a subtree is counted once per use, and loads: 2⁴
  // instances of one triangle.
  std::string shared = "<node id=\"n0\"><instance_geometry url=\"#tri\"/></node>";
  for (int k = 1; k <= 4; ++k)
    shared += "<node id=\"n" + std::to_string(k) + "\"><instance_node url=\"#n" + std::to_string(k - 1) +
              "\"/><instance_node url=\"#n" + std::to_string(k - 1) + "\"/></node>";
  EXPECT_EQ(meshError(collada("<node id=\"r\"><instance_node url=\"#n4\"/></node>", shared), "dag.dae"),
            "(loaded 16 triangles)");  // 16 placed copies of the one triangle
}

// Issue 41, reproducers 3–5: formats appell does not read are refused by
// content before any importer runs — a 20 000-deep glTF chain, NFF and AC3D
// (whose polygons reached an ai_assert abort in assimp's triangulation) —
// whatever their name; an STL named .obj is read as STL.
TEST(FuzzRegressions, OnlyTheFourMeshFormatsReachAnImporter) {
  std::string gltf = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[";
  for (int k = 0; k < 20000; ++k) gltf += "{\"children\":[" + std::to_string(k + 1) + "]},";
  gltf += "{}]}";
  for (const char* file : {"chain.gltf", "chain.stl"}) {
    const std::string m = meshError(gltf, file);
    EXPECT_NE(m.find(std::string(file) + ": a JSON (glTF?) file: not a mesh format appell reads (STL, OBJ, PLY or Collada"),
              std::string::npos)
        << m;
  }
  EXPECT_NE(meshError("v\nfrom 0 0 5\nat 0 0 0\np 3\n0 0 0\n1 0 0\n0 1 0\n", "scene.nff")
                .find("a text file of another format: not a mesh format appell reads"),
            std::string::npos);
  EXPECT_NE(meshError("AC3Db\nOBJECT world\nkids 0\n", "model.obj").find("a file starting with \"AC3D\""),
            std::string::npos);
  EXPECT_NE(meshError("glTF\x02\0\0\0", "model.glb").find("a binary glTF (.glb) file"), std::string::npos);
  EXPECT_EQ(meshError("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                      "endloop\nendfacet\nendsolid t\n",
                      "really_stl.obj"),
            "(loaded 1 triangles)");
  EXPECT_EQ(meshError("# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", "quad.OBJ"), "(loaded 2 triangles)");
  // PLY element counts the file cannot hold (assimp reserves them first).
  EXPECT_NE(meshError("ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n", "big.ply")
                .find("big.ply:3: PLY header line 'element vertex 4000000000': more elements than the file could hold"),
            std::string::npos);
  // A polygon of 10⁵ corners: refused before assimp triangulates it.
  std::string obj;
  for (int k = 0; k < 100000; ++k)
    obj += "v " + std::to_string(std::cos(2 * M_PI * k / 100000)) + " " + std::to_string(std::sin(2 * M_PI * k / 100000)) + " 0\n";
  obj += "f";
  for (int k = 1; k <= 100000; ++k) obj += " " + std::to_string(k);
  obj += "\n";
  EXPECT_NE(meshError(obj, "disk.obj").find("has 100000 corners (at most 1024 are triangulated)"), std::string::npos)
      << meshError(obj, "disk.obj");
  // A directory is not "not found".
  EXPECT_NE(meshError("", "empty.stl").find("empty.stl"), std::string::npos);
  try {
    loadMesh(::testing::TempDir());
    ADD_FAILURE() << "a directory loaded as a mesh";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory, not a mesh file"), std::string::npos) << e.what();
  }
}
