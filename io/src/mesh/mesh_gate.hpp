// The one gate every mesh file passes before assimp sees it — collision,
// terrain and visual meshes alike (a visual mesh's refusal becomes a warning
// in the caller). assimp 5.2.5 recognises some forty formats by content, and
// several of its importers crash, abort or run out of memory on small
// hostile files (issue 41: a Collada <instance_node> naming itself recurses
// for ever; 2²⁴ node instances from 2.7 KB take 8 GB; node trees 8 000 deep
// overflow the stack; an ai_assert in its triangulation aborts through the
// NFF and AC3D importers). So:
//   1. the file is read here, bounded (a regular file of at most
//      kMaxMeshBytes), and its format sniffed from its content — never from
//      its name — among the four appell reads: STL (binary or ASCII), OBJ,
//      PLY, Collada; anything else is refused by what it looks like;
//   2. each format's declared sizes are checked against what the file could
//      hold (Collada counts and index lists, PLY element counts), and a
//      Collada node graph is bounded (nesting depth, instance cycles, node
//      instances once expanded) before any importer runs;
//   3. the caller hands assimp the bytes with the sniffed format as the only
//      importer it may use (mesh.cpp), bounds the polygon size before
//      assimp triangulates, and the vertices it walks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace appell::io {

enum class MeshFormat { BinaryStl, AsciiStl, Obj, Ply, Collada };

/// Larger mesh files are refused (a 10⁶-triangle binary STL is 48 MiB).
constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{256} << 20;
/// Collada: XML elements nested deeper than this are refused (assimp's
/// Collada reader recurses per <node> level; a CAD assembly nests ~20).
constexpr int kMaxColladaDepth = 256;
/// Collada: node instances once every <instance_node> is expanded (assimp
/// copies the node tree per instance).
constexpr long kMaxColladaNodes = 100000;
/// Polygons with more corners are refused before assimp triangulates them
/// (its ear clipping is quadratic in the corners).
constexpr unsigned kMaxFaceCorners = 1024;
/// Vertices of all mesh instances placed by the node tree.
constexpr std::size_t kMaxMeshVertices = 20000000;

/// The file's bytes and their format. Throws SceneError naming `path`: not
/// found, a directory or device, too large, or not one of the four formats.
struct MeshFile {
  MeshFormat format;
  std::string bytes;
};
MeshFile readMeshFile(const std::string& path);

const char* formatName(MeshFormat format);   ///< "binary STL", "Collada", …
const char* assimpHint(MeshFormat format);   ///< the one importer assimp may use: "stl", …

/// Collada number lists and counts (collada_numbers.cpp), the node graph
/// (collada_structure.cpp), PLY element counts (mesh_gate.cpp). Each throws
/// SceneError naming the file, the line and the element.
void checkColladaNumbers(const std::string& path, const std::string& text);
void checkColladaStructure(const std::string& path, const std::string& text);
void checkPlyHeader(const std::string& path, const std::string& bytes);

/// 1-based line of byte offset `at`.
long lineAt(const std::string& text, std::size_t at);

}  // namespace appell::io
