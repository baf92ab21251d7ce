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
