// libFuzzer target: mesh files through the same loadMesh the scene loader
// calls — the mesh gate (mesh/mesh_gate.hpp: a bounded read, the format
// sniffed from the content, declared sizes and Collada's node graph bounded),
// then assimp with the one importer of the sniffed format, then appell's
// checks (face indices, finiteness, welding). The first byte picks the file's
// name among every suffix assimp 5.2.5 recognises (and none), the rest is the
// file: whatever the name says, only the content decides which importer runs,
// and formats appell does not read must be refused before any does. The
// seeds (scripts/fuzz.sh) hold a file of each format assimp sniffs by content.
#include <appell/urdf.hpp>

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* kSuffix[] = {".stl", ".obj", ".ply", ".dae", ".xml", ".zae", "",      ".nff",
                                  ".ac",  ".off", ".gltf", ".glb", ".3ds", ".x",   ".fbx", ".blend",
                                  ".ase", ".lwo", ".ms3d", ".md2", ".smd", ".raw", ".ter", ".irr",
                                  ".b3d", ".cob", ".ogex", ".3mf", ".amf", ".x3d", ".q3o", ".md5mesh"};
  constexpr std::size_t kSuffixes = sizeof kSuffix / sizeof kSuffix[0];
  const std::string path = "/tmp/appell_fuzz_mesh_" + std::to_string(::getpid()) + kSuffix[data[0] % kSuffixes];
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
