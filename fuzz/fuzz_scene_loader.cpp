// libFuzzer target: the scene loader on arbitrary bytes, as `appell info`
// reads a file — a URDF with its <appell> block, meshes named relative to the
// examples folder (so mutated names can reach real STL/OBJ/Collada files).
// Every outcome but an exception is a bug the sanitizers report: a crash, an
// out-of-bounds read, undefined behaviour, a hang (-timeout), a memory blow-up
// (-rss_limit_mb). scripts/fuzz.sh builds and runs it.
#include <appell/urdf.hpp>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string xml(reinterpret_cast<const char*>(data), size);
  appell::LoadOptions options;
  options.use_ros_package_path = false;
  options.package_paths = {APPELL_SOURCE_DIR "/tests/data/io/pkgroot"};
  try {
    const appell::Scene scene =
        appell::loadSceneFromString(xml, APPELL_SOURCE_DIR "/examples/diff_drive", "fuzz.urdf", options);
    (void)scene;
  } catch (const std::exception&) {
    // A refused file: what bad input should get.
  }
  return 0;
}
