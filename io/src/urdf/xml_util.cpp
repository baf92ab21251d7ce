#include "urdf/xml_util.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace appell::io {

std::string clipped(const std::string& value, std::size_t keep) {
  if (value.size() <= keep) return value;
  return value.substr(0, keep) + "… (" + std::to_string(value.size()) + " characters)";
}

std::string describe(const TiXmlElement* e) {
  std::string s = "<" + clipped(e->Value());
  if (const char* n = e->Attribute("name")) s += " name=\"" + clipped(n) + "\"";
  else if (const char* l = e->Attribute("link")) s += " link=\"" + clipped(l) + "\"";
  return s + ">";
}

namespace {
/// Every quoted value ('…' or "…") of a message, clipped: a message echoes
/// the user's values, which may be megabytes long.
std::string clipQuoted(const std::string& reason) {
  if (reason.size() <= 256) return reason;
  std::string out;
  out.reserve(512);
  for (std::size_t i = 0; i < reason.size();) {
    const char c = reason[i];
    if (c == '\'' || c == '"') {
      // The quoted value whole (a short one too: its closing quote must not
      // open the next one), clipped when long.
      const std::size_t end = reason.find(c, i + 1);
      if (end != std::string::npos) {
        out += c;
        out += clipped(reason.substr(i + 1, end - i - 1));
        out += c;
        i = end + 1;
        continue;
      }
      // A short quoted span is kept whole: its closing quote must not open
      // the next span (the text between two quoted names is not a value).
      if (end != std::string::npos) {
        out.append(reason, i, end - i + 1);
        i = end + 1;
        continue;
      }
    }
    out += c;
    ++i;
  }
  return out;
}
}  // namespace

const std::string& XmlSource::fileOf(const TiXmlElement* e) const {
  return e && scene_document && e->GetDocument() == scene_document ? scene_file : file;
}

std::string where(const XmlSource& src, const TiXmlElement* e) {
  std::string at = src.fileOf(e);
  if (e && e->Row() > 0) at += ":" + std::to_string(e->Row());
  return at;
}

std::string located(const XmlSource& src, const TiXmlElement* e, const std::string& reason) {
  return where(src, e) + ": " + (e ? describe(e) + ": " : std::string()) + clipQuoted(reason);
}

void fail(const XmlSource& src, const TiXmlElement* e, const std::string& reason) {
  throw SceneError(located(src, e, reason));
}

void fail(const XmlSource& src, const std::string& reason) {
  throw SceneError(src.file + ": " + clipQuoted(reason));
}

std::optional<double> parseNumber(const std::string& str, bool* finite) {
  std::size_t b = str.find_first_not_of(" \t\r\n");
  std::size_t e = str.find_last_not_of(" \t\r\n");
  if (b == std::string::npos) return std::nullopt;
  const char* first = str.data() + b;
  const char* last = str.data() + e + 1;
  if (*first == '+') ++first;  // from_chars does not take a leading '+'
  double x = 0;
  const auto r = std::from_chars(first, last, x);
  if (r.ec == std::errc::result_out_of_range && r.ptr == last) {
    // A number, but beyond the doubles (1e309) or below their smallest (1e-400):
    // the first is reported as not finite, the second reads as zero.
    const bool huge = std::abs(std::strtod(std::string(first, last).c_str(), nullptr)) > 1;
    if (finite) *finite = !huge;
    return huge ? std::numeric_limits<double>::infinity() : 0.0;
  }
  if (r.ec != std::errc() || r.ptr != last) return std::nullopt;
  if (finite) *finite = std::isfinite(x);
  return x;
}

bool has(const TiXmlElement* e, const char* attr) { return e->Attribute(attr) != nullptr; }

std::string text(const XmlSource& src, const TiXmlElement* e, const char* attr) {
  const char* a = e->Attribute(attr);
  if (!a) fail(src, e, std::string("missing attribute '") + attr + "'");
  return a;
}

std::string text(const TiXmlElement* e, const char* attr, const std::string& fallback) {
  const char* a = e->Attribute(attr);
  return a ? std::string(a) : fallback;
}

std::vector<double> numbers(const XmlSource& src, const TiXmlElement* e, const char* attr,
                            int count) {
  const std::string s = text(src, e, attr);
  std::istringstream in(s);
  std::vector<double> out;
  std::string word;
  while (in >> word) {
    bool finite = true;
    const auto x = parseNumber(word, &finite);
    if (!x)
      fail(src, e, std::string("attribute '") + attr + "': \"" + clipped(word) + "\" is not a number");
    if (!finite)
      fail(src, e, std::string("attribute '") + attr + "': \"" + clipped(word) +
                       "\" is not finite (out of the range of doubles, ±1.8e308)");
    out.push_back(*x);
  }
  if (count >= 0 && static_cast<int>(out.size()) != count)
    fail(src, e, std::string("attribute '") + attr + "' needs " + std::to_string(count) +
                     " numbers, got " + std::to_string(out.size()) + " (\"" + clipped(s) + "\")");
  if (count < 0 && out.empty()) fail(src, e, std::string("attribute '") + attr + "' is empty");
  return out;
}

double number(const XmlSource& src, const TiXmlElement* e, const char* attr) {
  return numbers(src, e, attr, 1)[0];
}

double number(const XmlSource& src, const TiXmlElement* e, const char* attr, double fallback) {
  return has(e, attr) ? number(src, e, attr) : fallback;
}

Vec3 vec3(const XmlSource& src, const TiXmlElement* e, const char* attr) {
  const auto v = numbers(src, e, attr, 3);
  return {v[0], v[1], v[2]};
}

Vec3 vec3(const XmlSource& src, const TiXmlElement* e, const char* attr, const Vec3& fallback) {
  return has(e, attr) ? vec3(src, e, attr) : fallback;
}

void allowOnly(const XmlSource& src, const TiXmlElement* e, std::initializer_list<const char*> allowed) {
  for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
    bool ok = false;
    for (const char* name : allowed) ok = ok || std::string(a->Name()) == name;
    if (ok) continue;
    std::string list;
    for (const char* name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
    fail(src, e, "unknown attribute '" + std::string(a->Name()) + "' (allowed here: " +
                     (list.empty() ? std::string("none") : list) + ")");
  }
}

Mat3 rpyToMatrix(const Vec3& rpy) {
  return axisAngle(Vec3::UnitZ(), rpy.z()) * axisAngle(Vec3::UnitY(), rpy.y()) *
         axisAngle(Vec3::UnitX(), rpy.x());
}

SE3 origin(const XmlSource& src, const TiXmlElement* e) {
  SE3 X;
  if (const TiXmlElement* o = e->FirstChildElement("origin")) {
    X.p = vec3(src, o, "xyz", Vec3::Zero());
    X.R = rpyToMatrix(vec3(src, o, "rpy", Vec3::Zero()));
  }
  return X;
}

std::size_t tagEnd(const std::string& text, std::size_t i) {
  char quote = 0;
  for (std::size_t j = i + 1; j < text.size(); ++j) {
    const char c = text[j];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      return j;
    }
  }
  return std::string::npos;
}

}  // namespace appell::io
