// The message for a name the scene gives that the robot does not have: a
// contact on a link, an initial state, effort or actuator on a joint. A
// scene file is written against a description it does not contain, so the
// message says which description was searched and, when one name is close
// (a typo: Levenshtein distance at most a third of the name, at most 3),
// which name was probably meant.
#include "scene/block.hpp"

#include <algorithm>

namespace appell::io {

namespace {

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

void failUnknownName(const XmlSource& src, const TiXmlElement* e, const std::string& kind,
                     const std::string& name, const std::vector<std::string>& names) {
  std::string reason = "unknown " + kind + " '" + name + "'";
  if (src.scene_document) reason += ": the robot description " + src.file + " has no " + kind + " of that name";
  // Names as long as a CAD export's are compared; a megabyte-long typo is not.
  const std::size_t budget = std::min<std::size_t>(3, name.size() / 3);
  std::string best;
  std::size_t best_distance = budget + 1;
  if (name.size() <= 256)
    for (const std::string& candidate : names) {
      if (candidate.size() > name.size() + budget || candidate.size() + budget < name.size()) continue;
      const std::size_t d = editDistance(name, candidate);
      if (d < best_distance) best_distance = d, best = candidate;
    }
  if (!best.empty()) reason += " (did you mean '" + best + "'?)";
  fail(src, e, reason);
}

}  // namespace appell::io
