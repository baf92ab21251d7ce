// libFuzzer target: mesh files through the same loadMesh the scene loader
// calls (assimp + appell's checks: face indices, welding, finiteness). The
// first byte picks the format by file suffix — STL, OBJ, PLY, Collada — and
// the rest is the file, written to a private temporary file.
#include <appell/urdf.hpp>

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* kSuffix[] = {".stl", ".obj", ".ply", ".dae"};
  const std::string path = "/tmp/appell_fuzz_mesh_" + std::to_string(::getpid()) + kSuffix[data[0] % 4];
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
  } else {
    return 0;
  }
  try {
    (void)appell::loadMesh(path);
  } catch (const std::exception&) {
    // A refused mesh: what bad input should get.
  }
  std::remove(path.c_str());
  return 0;
}
