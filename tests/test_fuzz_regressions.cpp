// Inputs the fuzzers found (scripts/fuzz.sh), kept in tests/data/fuzz-regressions:
// each must be refused or loaded cleanly — never a crash, and under the
// sanitizer build (scripts/sanitize.sh) never a memory error. Meshes (.stl,
// .obj, .ply, .dae) go through loadMesh, everything else through the scene
// loader. Findings named …_oom.… made a library allocate gigabytes and must
// be refused before it reads them.
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

using namespace appell;

TEST(FuzzRegressions, EveryFindingIsRefusedOrLoadedCleanly) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(APPELL_SOURCE_DIR) / "tests/data/fuzz-regressions";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path p = entry.path();
    const std::string ext = p.extension().string();
    ++files;
    // A finding that made a library allocate gigabytes (…_oom.…) must be
    // refused before the library reads it.
    const bool must_refuse = p.filename().string().find("_oom") != std::string::npos;
    try {
      if (ext == ".stl" || ext == ".obj" || ext == ".ply" || ext == ".dae") {
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
  refused(p, "<p>98765432109876 " + p.substr(3), "<p>: an index or count larger than the file could hold");
  refused("count=\"3270\"", "count=\"3270000000\"", "more values than the file could hold");
  refused("0.0796148", "0.07x6148", "<float_array>: a number list holds 'x'");
  refused("array\" count=\"3270\"", "array\" mater=\"3270\"", "<float_array>: has no count attribute");
  // The undamaged file loads.
  EXPECT_EQ(loadMesh((fs::path(APPELL_SOURCE_DIR) / "examples/diff_drive/meshes/wheel.dae").string()).triangles.size(), 2176u);
}
