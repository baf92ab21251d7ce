// The replay page's data (appell/replay.hpp), read back as JSON: its top-level
// keys are exactly the ones viewer/src/main.js reads (`data.<key>`), every
// per-frame array has the length the scene gives it (7 per body, 3 per
// constraint, 1 per constraint, 7 per support), the times and λ-derived
// values read back to the CSV's doubles, body quaternions are unit, and the
// geometry and support entries carry the fields of their type.
#include <appell/replay.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <charconv>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace appell {
namespace {

// A JSON value and a strict reader for the subset the page data uses.
struct Json {
  enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
  bool boolean = false;
  double number = 0;
  std::string text;
  std::vector<Json> items;
  std::map<std::string, Json> members;
  const Json& operator[](const std::string& k) const {
    const auto it = members.find(k);
    if (it == members.end()) throw std::runtime_error("no key '" + k + "'");
    return it->second;
  }
};

class Reader {
 public:
  explicit Reader(const std::string& s) : s_(s) {}
  Json document() {
    Json v = value();
    if (at_ != s_.size()) fail("text after the document");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("JSON at " + std::to_string(at_) + ": " + why);
  }
  char peek() const { return at_ < s_.size() ? s_[at_] : '\0'; }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++at_;
  }
  bool word(const char* w) {
    const std::string t(w);
    if (s_.compare(at_, t.size(), t) != 0) return false;
    at_ += t.size();
    return true;
  }
  Json value() {
    Json v;
    const char c = peek();
    if (c == '{') return object();
    if (c == '[') return array();
    if (c == '"') {
      v.kind = Json::String;
      v.text = string();
    } else if (word("null")) {
    } else if (word("true") || word("false")) {
      v.kind = Json::Bool;
      v.boolean = s_[at_ - 1] == 'e' && s_[at_ - 2] == 'u';
    } else {
      v.kind = Json::Number;
      const auto [end, ec] = std::from_chars(s_.data() + at_, s_.data() + s_.size(), v.number);
      if (ec != std::errc()) fail("not a value");
      at_ = static_cast<std::size_t>(end - s_.data());
    }
    return v;
  }
  std::string string() {
    expect('"');
    std::string out;
    while (peek() != '"') {
      if (at_ >= s_.size()) fail("unterminated string");
      char c = s_[at_++];
      if (static_cast<unsigned char>(c) < 0x20) fail("raw control character in a string");
      if (c == '\\') {
        c = s_[at_++];
        if (c == 'u') {
          out += static_cast<char>(std::stoi(s_.substr(at_, 4), nullptr, 16));
          at_ += 4;
          continue;
        }
        if (c != '"' && c != '\\') fail("unexpected escape");
      }
      out += c;
    }
    ++at_;
    return out;
  }
  Json array() {
    Json v;
    v.kind = Json::Array;
    expect('[');
    while (peek() != ']') {
      if (!v.items.empty()) expect(',');
      v.items.push_back(value());
    }
    ++at_;
    return v;
  }
  Json object() {
    Json v;
    v.kind = Json::Object;
    expect('{');
    while (peek() != '}') {
      if (!v.members.empty()) expect(',');
      const std::string k = string();
      expect(':');
      if (!v.members.emplace(k, value()).second) fail("duplicate key '" + k + "'");
    }
    ++at_;
    return v;
  }
  const std::string& s_;
  std::size_t at_ = 0;
};

std::set<std::string> keysTheViewerReads() {
  std::ifstream in(std::string(APPELL_SOURCE_DIR) + "/viewer/src/main.js");
  std::stringstream text;
  text << in.rdbuf();
  const std::string js = text.str();
  std::set<std::string> keys;
  const std::regex use(R"(\bdata\.([A-Za-z_]+))");
  for (auto it = std::sregex_iterator(js.begin(), js.end(), use); it != std::sregex_iterator(); ++it)
    keys.insert((*it)[1]);
  return keys;
}

struct Replayed {
  Scene scene;
  TrajectoryTable table;
  std::vector<ReplayFrame> frames;
  Json doc;
};

// The example run for `duration`, its CSV read back, replayed and parsed.
Replayed replay(const std::string& example, double duration) {
  Replayed r{loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/" + example), {}, {}, {}};
  RunOptions o = runOptions(r.scene.settings);
  o.duration = duration;
  const std::string csv = ::testing::TempDir() + "replay_schema.csv";
  {
    std::ofstream out(csv);
    TrajectoryWriter writer(out, r.scene);
    const RunSummary s = runScene(r.scene, o, writer);
    EXPECT_TRUE(s.ok) << s.failure;
  }
  r.table = readTrajectory(csv);
  r.frames = replayFrames(r.scene, r.table);
  const std::string text = replayJson(r.scene, r.frames);
  EXPECT_EQ(text.find('<'), std::string::npos) << "a '<' would let '</script>' close the page's script";
  r.doc = Reader(text).document();
  return r;
}

void expectPerFrame(const Json& doc, const char* key, std::size_t frames, std::size_t width) {
  const Json& a = doc[key];
  ASSERT_EQ(a.kind, Json::Array) << key;
  ASSERT_EQ(a.items.size(), frames) << key;
  for (const Json& f : a.items) {
    ASSERT_EQ(f.items.size(), width) << key;
    for (const Json& x : f.items) EXPECT_EQ(x.kind, Json::Number) << key;
  }
}

TEST(Replay, TheTumblingCratesPageDataHasTheViewersSchema) {
  const Replayed r = replay("tumbling_crate/tumbling_crate.urdf", 0.5);
  const Scene& s = r.scene;
  std::set<std::string> keys;
  for (const auto& [k, v] : r.doc.members) keys.insert(k);
  EXPECT_EQ(keys, keysTheViewerReads());

  const std::size_t n = r.table.rows.size(), nb = s.model.nbodies, nc = s.constraints.size();
  ASSERT_GT(n, 2u);
  const Json& times = r.doc["times"];
  ASSERT_EQ(times.items.size(), n);
  for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(times.items[k].number, r.table.rows[k][0]);  // exact
  expectPerFrame(r.doc, "poses", n, 7 * nb);
  expectPerFrame(r.doc, "points", n, 3 * nc);
  expectPerFrame(r.doc, "forces", n, 3 * nc);
  expectPerFrame(r.doc, "closed", n, nc);
  expectPerFrame(r.doc, "supportPoses", n, 7 * s.supports.size());
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t b = 0; b < nb; ++b) {
      const auto& p = r.doc["poses"].items[k].items;
      double norm2 = 0;
      for (int i = 3; i < 7; ++i) norm2 += p[7 * b + i].number * p[7 * b + i].number;
      EXPECT_NEAR(norm2, 1.0, 1e-12);
    }
    for (std::size_t c = 0; c < nc; ++c) {
      const double closed = r.doc["closed"].items[k].items[c].number;
      EXPECT_TRUE(closed == 0 || closed == 1);
      // The numbers are the frames' own doubles, read back exactly.
      for (int i = 0; i < 3; ++i)
        EXPECT_EQ(r.doc["forces"].items[k].items[3 * c + i].number, r.frames[k].forces[3 * c + i]);
    }
  }
  // The crate lands: its contacts' events are on the time line.
  const Json& events = r.doc["events"];
  EXPECT_GT(events.items.size(), 0u);
  for (const Json& e : events.items) {
    ASSERT_EQ(e.items.size(), 3u);
    EXPECT_LT(e.items[1].number, static_cast<double>(nc));
    EXPECT_EQ(e.items[2].kind, Json::String);
  }

  ASSERT_EQ(r.doc["bodies"].items.size(), nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const Json& body = r.doc["bodies"].items[b];
    EXPECT_EQ(body["name"].text, s.model.body_names[b]);
    EXPECT_EQ(body["moves"].kind, Json::Bool);
    for (const Json& g : body["geometry"].items) {
      const std::string& type = g["type"].text;
      const std::map<std::string, std::vector<std::string>> fields = {
          {"box", {"size"}}, {"sphere", {"radius"}}, {"cylinder", {"radius", "length"}},
          {"mesh", {"vertices", "triangles"}}};
      ASSERT_TRUE(fields.count(type)) << type;
      for (const std::string& f : fields.at(type)) EXPECT_TRUE(g.members.count(f)) << type << " " << f;
      EXPECT_EQ(g["p"].items.size(), 3u);
      EXPECT_EQ(g["q"].items.size(), 4u);
    }
  }
  EXPECT_TRUE(r.doc["bodies"].items.front()["moves"].boolean);  // the crate falls
  ASSERT_EQ(r.doc["contacts"].items.size(), nc);
  for (std::size_t c = 0; c < nc; ++c)
    EXPECT_EQ(r.doc["contacts"].items[c]["name"].text, s.constraints[c]->name());
  ASSERT_EQ(r.doc["supports"].items.size(), s.supports.size());
  for (std::size_t k = 0; k < s.supports.size(); ++k)
    EXPECT_EQ(r.doc["supports"].items[k]["name"].text, s.supports[k].name);
  EXPECT_EQ(r.doc["supports"].items.front()["type"].text, "ground");  // the floor z = 0
  EXPECT_EQ(r.doc["ground"].number, 0.0);
  EXPECT_GT(r.doc["size"].number, 0.0);
}

}  // namespace
}  // namespace appell
