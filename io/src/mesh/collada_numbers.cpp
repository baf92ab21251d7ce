// Collada's number lists must hold numbers only: indices (<p>, <v>,
// <vcount>, <int_array>) unsigned integers no larger than the file could
// hold values for, coordinates (<float_array>) decimal numbers, and every
// count="N" no larger than the file. assimp 5.2.5 reads a corrupted index
// list — a stray byte, or coordinates pasted into a <p> — as indices of
// billions and allocates gigabytes for them (13 GB and 40 s before
// std::bad_alloc), and dereferences a missing count (a segfault); all found
// by the mesh fuzzer (tests/data/fuzz-regressions/assimp_dae_*). So the
// lists are checked before assimp sees the file, and the first bad one is
// named with its line.
#include "mesh/mesh_gate.hpp"

#include <appell/urdf.hpp>

#include <cctype>
#include <cstdio>
#include <cstring>

namespace appell::io {

namespace {

// Every count="N" (arrays, accessors, primitives): assimp reserves N.
void checkCounts(const std::string& path, const std::string& text) {
  for (std::size_t at = text.find("count=\""); at != std::string::npos; at = text.find("count=\"", at + 1)) {
    std::size_t value = 0, k = at + 7;
    for (; k < text.size() && std::isdigit(static_cast<unsigned char>(text[k])); ++k) {
      value = value * 10 + static_cast<std::size_t>(text[k] - '0');
      if (value > text.size())
        throw SceneError(path + ":" + std::to_string(lineAt(text, at)) + ": count=\"" +
                         text.substr(at + 7, k - at - 6) +
                         "…\": more values than the file could hold: the file is damaged");
    }
  }
}

// Arrays, accessors and primitives must say how many values they hold
// (assimp 5.2.5 dereferences a missing count).
void checkCountAttributes(const std::string& path, const std::string& text) {
  for (const char* tag : {"<float_array", "<int_array", "<accessor", "<triangles", "<polylist",
                          "<polygons", "<lines", "<linestrips", "<trifans", "<tristrips"}) {
    const std::size_t len = std::strlen(tag);
    for (std::size_t at = text.find(tag); at != std::string::npos; at = text.find(tag, at + 1)) {
      const char after = at + len < text.size() ? text[at + len] : '>';
      if (!std::isspace(static_cast<unsigned char>(after)) && after != '>' && after != '/') continue;
      const std::size_t open_end = text.find('>', at);
      const std::string open = text.substr(at, open_end == std::string::npos ? std::string::npos : open_end - at);
      if (open.find(" count=\"") == std::string::npos && open.find("\tcount=\"") == std::string::npos &&
          open.find("\ncount=\"") == std::string::npos)
        throw SceneError(path + ":" + std::to_string(lineAt(text, at)) + ": " + std::string(tag) +
                         ">: has no count attribute (Collada requires it): the file is damaged");
    }
  }
}

// An array holds the number of values its count declares. assimp 5.2.5
// trusts the count: a <float_array count="0"> holding a triangle's nine
// coordinates, read by an accessor of three points, was a null dereference
// inside assimp (the mesh fuzzer, 2026-11-27:
// tests/data/fuzz-regressions/mesh_dae_array_count_segv_refused.dae).
void checkArrayCount(const std::string& path, const std::string& text, std::size_t at,
                     std::size_t open_end, const std::string& name, std::size_t values) {
  const std::string open = text.substr(at, open_end - at);
  const std::size_t c = open.find("count=\"");
  if (c == std::string::npos) return;  // (checkCountAttributes names it)
  std::size_t declared = 0;
  for (std::size_t k = c + 7; k < open.size() && std::isdigit(static_cast<unsigned char>(open[k])); ++k)
    declared = declared * 10 + static_cast<std::size_t>(open[k] - '0');
  if (declared != values)
    throw SceneError(path + ":" + std::to_string(lineAt(text, at)) + ": <" + name + ">: count=\"" +
                     std::to_string(declared) + "\" but it holds " + std::to_string(values) +
                     " values: the file is damaged");
}

// The text of each list element: digits (and, for coordinates, a decimal
// number's signs, point and exponent) and white space only.
void checkNumberLists(const std::string& path, const std::string& text) {
  struct List {
    const char* tag;
    bool indices;
  };
  static const List kLists[] = {{"<p>", true},       {"<p ", true},          {"<v>", true},
                                {"<v ", true},       {"<vcount", true},      {"<int_array", true},
                                {"<float_array", false}};
  for (const List& list : kLists) {
    for (std::size_t at = text.find(list.tag); at != std::string::npos; at = text.find(list.tag, at + 1)) {
      const std::size_t open_end = text.find('>', at);
      if (open_end == std::string::npos || text[open_end - 1] == '/') continue;
      const std::size_t close = text.find('<', open_end + 1);
      if (close == std::string::npos) break;
      std::string name(list.tag + 1);
      if (name.back() == ' ' || name.back() == '>') name.pop_back();
      auto bad = [&](std::size_t k, const std::string& why) {
        throw SceneError(path + ":" + std::to_string(lineAt(text, k)) + ": <" + name + ">: " + why +
                         ": the file is damaged");
      };
      std::size_t value = 0, values = 0;
      bool in_value = false;
      for (std::size_t k = open_end + 1; k < close; ++k) {
        const unsigned char c = static_cast<unsigned char>(text[k]);
        // The separators every exporter writes, tested inline (a published
        // robot's visual meshes hold 10⁶ characters of numbers, and a libc
        // call per character was a sixth of `appell info`'s time on ANYmal).
        // Not '\v' or '\f': assimp 5.2.5's tokenizers disagree on them — a
        // form feed in a <p> of a file led by a control byte made it allocate
        // 3.4 GB (the mesh fuzzer, 2026-11-27:
        // tests/data/fuzz-regressions/mesh_dae_formfeed_index_oom.dae).
        if (c == ' ' || c == '\n' || c == '\t' || c == '\r') {
          value = 0;
          in_value = false;
          continue;
        }
        values += in_value ? 0 : 1;
        in_value = true;
        const bool digit = c >= '0' && c <= '9';
        const bool ok = digit || (!list.indices && (c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E'));
        if (!ok) {
          char shown[8];
          std::snprintf(shown, sizeof shown, std::isprint(c) ? "'%c'" : "0x%02x", c);
          bad(k, std::string(list.indices ? "an index" : "a number") + " list holds " + shown);
        }
        if (list.indices) {
          value = value * 10 + static_cast<std::size_t>(c - '0');
          if (value > text.size()) bad(k, "an index or count larger than the file could hold values for");
        }
      }
      if (name == "float_array" || name == "int_array") checkArrayCount(path, text, at, open_end, name, values);
      at = close;
    }
  }
}

}  // namespace

void checkColladaNumbers(const std::string& path, const std::string& text) {
  checkCounts(path, text);
  checkCountAttributes(path, text);
  checkNumberLists(path, text);
}

}  // namespace appell::io
