// A Collada file's node graph, bounded before assimp builds it. assimp 5.2.5
// recurses once per <node> level while reading and again while resolving
// <instance_node> references, and copies a node's subtree per instance, so:
//   - XML nested deeper than kMaxColladaDepth is refused (8 000 nested
//     nodes overflowed its stack);
//   - an <instance_node> that leads back to a node it sits in is a cycle
//     (infinite recursion: a segfault, even for a visual mesh);
//   - the tree once every instance is expanded may hold at most
//     kMaxColladaNodes nodes and be at most kMaxColladaDepth deep (2.7 KB
//     of 24 nodes each instancing the previous one twice is 2²⁴ nodes:
//     70 s and 8.4 GB inside assimp).
// The scan is a tokenizer, not a parser: it classifies each '<' as an XML
// parser would (comments, CDATA, declarations, end tags, elements with
// quoted attribute values) and keeps only <node> elements, their ids and
// their <instance_node url="#id">s. The graph is then walked with an explicit
// stack (no recursion of our own).
#include "mesh/mesh_gate.hpp"
#include "urdf/xml_util.hpp"

#include <appell/urdf.hpp>

#include <algorithm>
#include <unordered_map>
#include <vector>

namespace appell::io {

namespace {

struct Node {
  std::string id;
  std::size_t at = 0;                 // offset of its tag, for the line
  std::vector<int> children;          // nested <node>s
  std::vector<std::string> instances; // <instance_node url="#id"> targets (without '#')
  bool in_scene = false;              // a direct child of a <visual_scene>
};

// The value of attribute `name` in the start tag text[begin, end), or "".
std::string attribute(const std::string& text, std::size_t begin, std::size_t end, const std::string& name) {
  for (std::size_t at = text.find(name + "=", begin); at != std::string::npos && at < end;
       at = text.find(name + "=", at + 1)) {
    if (!std::isspace(static_cast<unsigned char>(text[at - 1]))) continue;  // "sid=" is not "id="
    const std::size_t q = at + name.size() + 1;
    if (q >= end || (text[q] != '"' && text[q] != '\'')) return "";
    const std::size_t close = text.find(text[q], q + 1);
    if (close == std::string::npos || close > end) return "";
    return text.substr(q + 1, close - q - 1);
  }
  return "";
}


std::string elementName(const std::string& text, std::size_t i, std::size_t end) {
  std::size_t k = i + 1;
  while (k < end && !std::isspace(static_cast<unsigned char>(text[k])) && text[k] != '/' && text[k] != '>') ++k;
  return text.substr(i + 1, k - i - 1);
}

// Every <node> with its nesting and instances; throws past kMaxColladaDepth.
std::vector<Node> readNodes(const std::string& path, const std::string& text) {
  std::vector<Node> nodes;
  std::vector<std::pair<std::string, int>> open;  // element name, its node (or −1)
  for (std::size_t i = text.find('<'); i != std::string::npos; i = text.find('<', i + 1)) {
    std::size_t end;
    if (text.compare(i, 4, "<!--") == 0) {
      end = text.find("-->", i + 4);
    } else if (text.compare(i, 9, "<![CDATA[") == 0) {
      end = text.find("]]>", i + 9);
    } else if (text.compare(i, 2, "<!") == 0 || text.compare(i, 2, "<?") == 0) {
      end = text.find('>', i);
    } else if (text.compare(i, 2, "</") == 0) {
      end = text.find('>', i);
      if (!open.empty()) open.pop_back();
    } else {
      end = tagEnd(text, i);
      if (end == std::string::npos) break;
      const std::string name = elementName(text, i, end);
      const bool empty = text[end - 1] == '/';
      int parent_node = -1;
      for (auto it = open.rbegin(); it != open.rend() && parent_node < 0; ++it) parent_node = it->second;
      int node = -1;
      if (name == "node") {
        node = static_cast<int>(nodes.size());
        nodes.push_back({attribute(text, i, end, "id"), i, {}, {}, !open.empty() && open.back().first == "visual_scene"});
        if (parent_node >= 0) nodes[parent_node].children.push_back(node);
      } else if (name == "instance_node" && parent_node >= 0) {
        const std::string url = attribute(text, i, end, "url");
        if (!url.empty() && url[0] == '#') nodes[parent_node].instances.push_back(url.substr(1));
      }
      if (!empty) open.emplace_back(name, node);
      if (static_cast<int>(open.size()) > kMaxColladaDepth)
        throw SceneError(path + ":" + std::to_string(lineAt(text, i)) + ": <" + name +
                         ">: elements nested more than " + std::to_string(kMaxColladaDepth) +
                         " deep (a Collada model needs a few dozen)");
    }
    if (end == std::string::npos) break;
    i = end;
  }
  return nodes;
}

// Expanded sizes of every node reachable from the visual scenes, post-order
// with an explicit stack; a node met again while it is open is a cycle.
void boundExpansion(const std::string& path, const std::string& text, const std::vector<Node>& nodes) {
  // An id should name one element, but a damaged file may give two nodes
  // one id, and which of them an importer resolves is its own choice: an
  // instance leads to every node of that id (a fuzzed file whose second
  // "n2" closed a cycle that the first did not overflowed assimp's stack).
  std::unordered_map<std::string, std::vector<int>> by_id;
  for (int k = 0; k < static_cast<int>(nodes.size()); ++k)
    if (!nodes[k].id.empty()) by_id[nodes[k].id].push_back(k);
  auto edges = [&](int k) {
    std::vector<int> out = nodes[k].children;
    for (const std::string& target : nodes[k].instances)
      if (auto it = by_id.find(target); it != by_id.end())
        out.insert(out.end(), it->second.begin(), it->second.end());
    return out;
  };
  enum State : char { Unseen, Open, Done };
  std::vector<State> state(nodes.size(), Unseen);
  std::vector<long> count(nodes.size(), 0), depth(nodes.size(), 0);
  long total = 0;
  auto where = [&](int k) {
    return path + ":" + std::to_string(lineAt(text, nodes[k].at)) + ": <node" +
           (nodes[k].id.empty() ? std::string() : " id=\"" + nodes[k].id + "\"") + ">: ";
  };
  for (int root = 0; root < static_cast<int>(nodes.size()); ++root) {
    if (!nodes[root].in_scene) continue;
    std::vector<std::pair<int, std::vector<int>>> stack;
    if (state[root] == Unseen) {
      state[root] = Open;
      stack.emplace_back(root, edges(root));
    }
    while (!stack.empty()) {
      auto& [k, next] = stack.back();
      if (!next.empty()) {
        const int c = next.back();
        next.pop_back();
        if (state[c] == Open)
          throw SceneError(where(c) + "instances itself (an <instance_node> below it leads back to it): "
                                      "a cycle no importer can expand");
        if (state[c] == Unseen) {
          state[c] = Open;
          stack.emplace_back(c, edges(c));
        }
        continue;
      }
      long n = 1, d = 1;
      for (int c : edges(k)) {
        n = std::min(n + count[c], kMaxColladaNodes + 1);
        d = std::max(d, depth[c] + 1);
      }
      count[k] = n;
      depth[k] = d;
      state[k] = Done;
      if (d > kMaxColladaDepth)
        throw SceneError(where(k) + "its node tree is " + std::to_string(d) + " levels deep once its " +
                         "<instance_node>s are expanded (at most " + std::to_string(kMaxColladaDepth) + ")");
      if (n > kMaxColladaNodes)
        throw SceneError(where(k) + "expands to more than " + std::to_string(kMaxColladaNodes) +
                         " nodes through its <instance_node>s");
      stack.pop_back();
    }
    total = std::min(total + count[root], kMaxColladaNodes + 1);
    if (total > kMaxColladaNodes)
      throw SceneError(path + ": the visual scene expands to more than " + std::to_string(kMaxColladaNodes) +
                       " nodes through its <instance_node>s");
  }
}

}  // namespace

void checkColladaStructure(const std::string& path, const std::string& text) {
  boundExpansion(path, text, readNodes(path, text));
}

}  // namespace appell::io
