// Reading a mesh file, bounded, and sniffing its format from its content
// (mesh_gate.hpp gives the rules and why).
#include "mesh/mesh_gate.hpp"

#include <appell/urdf.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace appell::io {

long lineAt(const std::string& text, std::size_t at) {
  return 1 + std::count(text.begin(), text.begin() + static_cast<long>(std::min(at, text.size())), '\n');
}

const char* formatName(MeshFormat format) {
  switch (format) {
    case MeshFormat::BinaryStl: return "binary STL";
    case MeshFormat::AsciiStl: return "ASCII STL";
    case MeshFormat::Obj: return "OBJ";
    case MeshFormat::Ply: return "PLY";
    case MeshFormat::Collada: return "Collada";
  }
  return "?";
}

const char* assimpHint(MeshFormat format) {
  switch (format) {
    case MeshFormat::BinaryStl:
    case MeshFormat::AsciiStl: return "stl";
    case MeshFormat::Obj: return "obj";
    case MeshFormat::Ply: return "ply";
    case MeshFormat::Collada: return "dae";
  }
  return "";
}

namespace {

bool startsWith(const std::string& s, std::size_t at, const char* prefix) {
  return s.compare(at, std::strlen(prefix), prefix) == 0;
}

// The first element's name of an XML text (after declarations and comments).
std::string rootElement(const std::string& text, std::size_t i) {
  while ((i = text.find('<', i)) != std::string::npos) {
    if (startsWith(text, i, "<!--")) {
      i = text.find("-->", i);
    } else if (startsWith(text, i, "<?") || startsWith(text, i, "<!")) {
      i = text.find('>', i);
    } else {
      std::size_t k = i + 1;
      while (k < text.size() && !std::isspace(static_cast<unsigned char>(text[k])) && text[k] != '>' && text[k] != '/') ++k;
      return text.substr(i + 1, std::min<std::size_t>(k - i - 1, 40));
    }
    if (i == std::string::npos) break;
  }
  return "";
}

// Whether the first line that is not blank or a comment is an OBJ statement
// (a vertex "v x y z", or another OBJ keyword followed by its arguments).
bool looksLikeObj(const std::string& text, std::size_t i) {
  std::istringstream lines(text.substr(i, 4096));
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string key;
    if (!(words >> key) || key[0] == '#') continue;
    if (key == "v" || key == "vn") {
      double x, y, z;
      return static_cast<bool>(words >> x >> y >> z);
    }
    static const char* kKeywords[] = {"vt", "vp", "f", "l", "p", "o", "g", "s", "mtllib", "usemtl"};
    std::string rest;
    return std::any_of(std::begin(kKeywords), std::end(kKeywords), [&](const char* k) { return key == k; }) &&
           static_cast<bool>(words >> rest);
  }
  return false;
}

// What a file appell does not read looks like, for the message.
std::string describeOther(const std::string& bytes, std::size_t i) {
  if (startsWith(bytes, 0, "glTF")) return "a binary glTF (.glb) file";
  if (startsWith(bytes, 0, "Kaydara FBX Binary")) return "an FBX file";
  if (startsWith(bytes, 0, "BLENDER")) return "a Blender file";
  if (startsWith(bytes, 0, "PK\x03\x04")) return "a zip archive (.zae, .3mf, …)";
  if (i < bytes.size() && bytes[i] == '{') return "a JSON (glTF?) file";
  if (i < bytes.size() && bytes[i] == '<') return "an XML file whose root is <" + rootElement(bytes, i) + ">";
  for (const char* magic : {"OFF", "AC3D", "xof ", "ISO-10303", "#VRML", "3DMetaFile"})
    if (startsWith(bytes, i, magic)) return std::string("a file starting with \"") + magic + "\"";
  const bool binary = std::find(bytes.begin(), bytes.begin() + static_cast<long>(std::min<std::size_t>(bytes.size(), 4096)),
                                '\0') != bytes.begin() + static_cast<long>(std::min<std::size_t>(bytes.size(), 4096));
  return binary ? "a binary file of another format" : "a text file of another format";
}

MeshFormat sniff(const std::string& path, const std::string& bytes) {
  // Binary STL: an 80-byte header, a facet count n, 50 bytes per facet —
  // the file is exactly 84 + 50 n bytes (assimp's own test, made first: a
  // binary STL's header may begin with "solid").
  if (bytes.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);  // little-endian on every platform appell builds for
    if (84 + 50 * static_cast<std::uint64_t>(n) == bytes.size()) return MeshFormat::BinaryStl;
  }
  std::size_t i = startsWith(bytes, 0, "\xEF\xBB\xBF") ? 3 : 0;  // a UTF-8 byte-order mark
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  if (startsWith(bytes, i, "ply") && i + 3 < bytes.size() && (bytes[i + 3] == '\n' || bytes[i + 3] == '\r'))
    return MeshFormat::Ply;
  if (startsWith(bytes, i, "solid")) return MeshFormat::AsciiStl;
  if (i < bytes.size() && bytes[i] == '<' && rootElement(bytes, i) == "COLLADA") return MeshFormat::Collada;
  if (looksLikeObj(bytes, i)) return MeshFormat::Obj;
  throw SceneError(path + ": " + describeOther(bytes, i) +
                   ": not a mesh format appell reads (STL, OBJ, PLY or Collada, recognised by content)");
}

std::string readBounded(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw SceneError(path + ": mesh file not found");
  if (std::filesystem::is_directory(status)) throw SceneError(path + ": is a directory, not a mesh file");
  if (!std::filesystem::is_regular_file(status))
    throw SceneError(path + ": not a regular file (a device, pipe or socket cannot be a mesh)");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw SceneError(path + ": cannot read the size of the mesh file");
  if (size > kMaxMeshBytes)
    throw SceneError(path + ": " + std::to_string(size) + " bytes, larger than the " +
                     std::to_string(kMaxMeshBytes >> 20) + " MiB a mesh file may have");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open the mesh file");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw SceneError(path + ": read error");
  return bytes;
}

}  // namespace

// PLY: the header must follow the format's grammar line by line (Turk,
// "The PLY polygon file format", 1994) — a damaged header of 187 bytes kept
// assimp's PLY reader looping for ever — and every "element NAME COUNT" must
// fit the file (each element takes at least one byte; assimp reserves COUNT
// before reading).
void checkPlyHeader(const std::string& path, const std::string& bytes) {
  const std::size_t end = bytes.find("\nend_header");
  if (end == std::string::npos || end > 65536)
    throw SceneError(path + ": PLY header without an end_header line in its first 64 KiB: the file is damaged");
  // The header is ASCII text: a NUL or a control byte inside a keyword let a
  // damaged header pass as words and crash the reader.
  for (std::size_t k = 0; k < end; ++k) {
    const unsigned char c = static_cast<unsigned char>(bytes[k]);
    if ((c < 0x20 && c != '\n' && c != '\r' && c != '\t') || c > 0x7E)
      throw SceneError(path + ":" + std::to_string(lineAt(bytes, k)) +
                       ": the PLY header holds a byte that is not ASCII text: the file is damaged");
  }
  // "end_header" alone on its line: what follows it is the data (a binary
  // body read from a misplaced start crashed assimp's reader).
  const std::size_t data = end + 11;
  const bool crlf = bytes.compare(data, 2, "\r\n") == 0;
  if (!crlf && bytes.compare(data, 1, "\n") != 0)
    throw SceneError(path + ":" + std::to_string(lineAt(bytes, data)) +
                     ": PLY header: 'end_header' must end its line: the file is damaged");
  const std::size_t body = data + (crlf ? 2 : 1);
  static const std::map<std::string, int> kTypes = {
      {"char", 1},  {"uchar", 1},  {"short", 2},  {"ushort", 2},  {"int", 4},     {"uint", 4},
      {"float", 4}, {"double", 8}, {"int8", 1},   {"uint8", 1},   {"int16", 2},   {"uint16", 2},
      {"int32", 4}, {"uint32", 4}, {"float32", 4}, {"float64", 8}};
  bool binary = false;
  std::uintmax_t least = 0, count = 0;  // bytes the declared elements need at least (binary)

  std::istringstream header(bytes.substr(0, end));
  std::string line;
  bool element_seen = false;
  for (long number = 1; std::getline(header, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream in(line);
    std::vector<std::string> w;
    for (std::string word; in >> word;) w.push_back(word);
    auto bad = [&](const std::string& why) {
      throw SceneError(path + ":" + std::to_string(number) + ": PLY header line '" + line.substr(0, 60) + "': " + why +
                       ": the file is damaged");
    };
    if (number == 1) {
      if (w.size() != 1 || w[0] != "ply") bad("the first line must be 'ply'");
    } else if (w.empty() || w[0] == "comment" || w[0] == "obj_info") {
      continue;
    } else if (w[0] == "format") {
      if (w.size() != 3 || (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad("not 'format ascii|binary_little_endian|binary_big_endian VERSION'");
      binary = w[1] != "ascii";
    } else if (w[0] == "element") {
      const bool digits = w.size() == 3 && w[2].size() <= 19 &&
                          std::all_of(w[2].begin(), w[2].end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
      if (!digits) bad("not 'element NAME COUNT'");
      if (std::stoull(w[2]) > bytes.size()) bad("more elements than the file could hold");
      count = std::stoull(w[2]);
      element_seen = true;
    } else if (w[0] == "property") {
      const bool scalar = w.size() == 3 && kTypes.count(w[1]);
      const bool list = w.size() == 5 && w[1] == "list" && kTypes.count(w[2]) && kTypes.count(w[3]);
      if (!scalar && !list) bad("not 'property TYPE NAME' or 'property list TYPE TYPE NAME'");
      if (!element_seen) bad("a property before any element");
      least += count * static_cast<std::uintmax_t>(kTypes.at(list ? w[2] : w[1]));  // a list: its count
    } else {
      bad("not a PLY header keyword");
    }
  }
  if (binary && least > bytes.size() - body)
    throw SceneError(path + ": the PLY header declares at least " + std::to_string(least) + " bytes of data, the file has " +
                     std::to_string(bytes.size() - body) + ": the file is damaged (cut short?)");
}

MeshFile readMeshFile(const std::string& path) {
  MeshFile file{MeshFormat::Obj, readBounded(path)};
  file.format = sniff(path, file.bytes);
  if (file.format == MeshFormat::Collada) {
    checkColladaNumbers(path, file.bytes);
    checkColladaStructure(path, file.bytes);
  } else if (file.format == MeshFormat::Ply) {
    checkPlyHeader(path, file.bytes);
  }
  return file;
}

}  // namespace appell::io
