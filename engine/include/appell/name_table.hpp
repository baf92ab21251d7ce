// Closed sets of names: one table per set (integrators, formulations, contact
// kinds, shapes), each entry with its canonical name, its aliases and a line
// of description. Parsing, the "known: …" list of an error message, the
// command-line help and the tests all read the same table, so a name cannot
// be accepted in one place and rejected in another.
//
// Matching treats '-' and '_' alike ("knife-edge" is "knife_edge") and is
// otherwise exact.
#pragma once

#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace appell {

/// One member of a closed set: the value, its canonical name, the other
/// spellings accepted for it, and what it is (for help texts and docs).
template <class E>
struct NamedValue {
  E value;
  const char* name;
  std::vector<const char*> aliases;
  const char* description;
};

/// True when a and b spell the same name ('-' and '_' are the same letter).
inline bool sameName(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const char x = a[i] == '-' ? '_' : a[i], y = b[i] == '-' ? '_' : b[i];
    if (x != y) return false;
  }
  return true;
}

/// True when `text` is the entry's name or one of its aliases.
template <class Entry>
bool matchesName(const Entry& entry, std::string_view text) {
  if (sameName(entry.name, text)) return true;
  for (const char* a : entry.aliases)
    if (sameName(a, text)) return true;
  return false;
}

/// The entry that `text` names, or nullptr.
template <class Entry>
const Entry* findByName(std::span<const Entry> table, std::string_view text) {
  for (const Entry& e : table)
    if (matchesName(e, text)) return &e;
  return nullptr;
}

/// "a (alias, alias), b, c": every accepted spelling, for error messages.
template <class Entry>
std::string knownNames(std::span<const Entry> table) {
  std::string s;
  for (const Entry& e : table) {
    if (!s.empty()) s += ", ";
    s += e.name;
    for (std::size_t k = 0; k < e.aliases.size(); ++k)
      s += (k == 0 ? " (" : ", ") + std::string(e.aliases[k]) + (k + 1 == e.aliases.size() ? ")" : "");
  }
  return s;
}

/// "a | b | c": the canonical names only, for usage lines.
template <class Entry>
std::string canonicalNames(std::span<const Entry> table, const char* separator = " | ") {
  std::string s;
  for (const Entry& e : table) s += (s.empty() ? "" : separator) + std::string(e.name);
  return s;
}

/// The value `text` names; throws std::invalid_argument
/// "unknown <what> '<text>' (known: …)" otherwise.
template <class E>
E parseName(std::span<const NamedValue<E>> table, std::string_view text, const char* what) {
  if (const NamedValue<E>* e = findByName(table, text)) return e->value;
  throw std::invalid_argument("unknown " + std::string(what) + " '" + std::string(text) +
                              "' (known: " + knownNames(table) + ")");
}

/// The entry of `value` (every value of a closed set has one).
template <class E>
const NamedValue<E>& entryOf(std::span<const NamedValue<E>> table, E value) {
  for (const NamedValue<E>& e : table)
    if (e.value == value) return e;
  throw std::logic_error("value missing from its name table");
}

}  // namespace appell
