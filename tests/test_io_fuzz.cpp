// Damaged scene files: whatever the damage, loading either succeeds or throws
// SceneError — no other exception, no crash, no partial scene.
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

using namespace appell;

namespace {

const std::string kData = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/";

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string mutate(std::string s, std::mt19937& rng) {
  static const std::string kChars = "<>/\"= 0123456789.-+eEnaifxyz\n";
  auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
  const int edits = 1 + static_cast<int>(pick(3));
  for (int k = 0; k < edits && !s.empty(); ++k) {
    const std::size_t at = pick(s.size());
    switch (pick(4)) {
      case 0: s.erase(at, 1 + pick(20)); break;                       // delete a run
      case 1: s[at] = kChars[pick(kChars.size())]; break;             // replace a char
      case 2: {                                                       // duplicate a line
        const std::size_t b = s.rfind('\n', at), e = s.find('\n', at);
        if (b != std::string::npos && e != std::string::npos) s.insert(e, s.substr(b, e - b));
        break;
      }
      default: s.resize(at); break;                                   // truncate
    }
  }
  return s;
}

}  // namespace

TEST(IoFuzz, DamagedFilesGiveSceneErrorsOnly) {
  LoadOptions opt;
  opt.package_paths = {kData + "pkgroot"};
  opt.use_ros_package_path = false;
  std::mt19937 rng(20261121);
  int loaded = 0, refused = 0;
  // More damage on request (e.g. 5000 for a long run); the default keeps the suite quick.
  const char* env = std::getenv("APPELL_IO_FUZZ_ITERATIONS");
  const int iterations = env ? std::atoi(env) : 150;
  for (const char* file : {"scenes/ball_turntable.urdf", "scenes/sleigh.urdf", "scenes/shapes.urdf",
                           "all_joints.urdf", "meshes.urdf"}) {
    const std::string original = read(kData + file);
    ASSERT_FALSE(original.empty()) << file;
    const std::string dir = kData + std::string(file).substr(0, std::string(file).rfind('/') + 1);
    for (int i = 0; i < iterations; ++i) {
      const std::string text = mutate(original, rng);
      try {
        const Scene s = loadSceneFromString(text, dir, file, opt);
        // A scene that loads is whole: state sizes match the model.
        EXPECT_EQ(s.q0.size(), s.model.nq);
        EXPECT_EQ(s.v0.size(), s.model.nv);
        EXPECT_EQ(s.constraints.size(), s.contacts.size() + s.joint_limits.size());
        EXPECT_EQ(static_cast<int>(s.geometry.size()), s.model.nbodies);
        ++loaded;
      } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(file, 0), 0u) << "message does not name the file: " << e.what();
        ++refused;
      } catch (const std::exception& e) {
        ADD_FAILURE() << file << " mutation " << i << ": " << typeid(e).name() << ": " << e.what()
                      << "\n--- text ---\n" << text;
      }
    }
  }
  // The damage must actually reach the loader's checks (and sometimes be harmless).
  EXPECT_GT(refused, iterations * 2);
  EXPECT_GT(loaded, iterations / 15);
  std::printf("loaded %d, refused %d\n", loaded, refused);
}
