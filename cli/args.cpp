#include "args.hpp"

#include <cmath>
#include <sstream>

namespace appell::cli {

Args::Args(int argc, char** argv, int first, const std::set<std::string>& valued,
           const std::set<std::string>& flags) {
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || a == "--") {
      positional_.push_back(a);
      continue;
    }
    std::string name = a.substr(2), value;
    const auto eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    if (flags.count(name)) {
      if (eq != std::string::npos) throw UsageError("option --" + name + " takes no value");
      values_[name] = "1";
    } else if (valued.count(name)) {
      if (eq == std::string::npos) {
        if (i + 1 >= argc) throw UsageError("option --" + name + " needs a value");
        value = argv[++i];
      }
      values_[name] = value;
      repeated_[name].push_back(value);
    } else {
      throw UsageError("unknown option --" + name);
    }
  }
}

const std::vector<std::string>& Args::all(const std::string& name) const {
  static const std::vector<std::string> none;
  auto it = repeated_.find(name);
  return it == repeated_.end() ? none : it->second;
}

std::string Args::text(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

double Args::number(const std::string& name, double fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  std::size_t used = 0;
  double x = 0;
  try {
    x = std::stod(it->second, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != it->second.size() || !std::isfinite(x))
    throw UsageError("option --" + name + ": '" + it->second + "' is not a finite number");
  return x;
}

double Args::positiveNumber(const std::string& name, double fallback) const {
  const double x = number(name, fallback);
  if (!(x > 0)) throw UsageError("option --" + name + " must be positive");
  return x;
}

double Args::nonNegativeNumber(const std::string& name) const {
  const double x = number(name, 0.0);
  if (!(x >= 0)) throw UsageError("option --" + name + " must be ≥ 0 (a lower bound; 0: none)");
  return x;
}

int Args::integer(const std::string& name, int fallback) const {
  const double x = number(name, fallback);
  if (x != std::floor(x) || std::abs(x) > 1e9)
    throw UsageError("option --" + name + " must be a whole number");
  return static_cast<int>(x);
}

std::vector<std::string> Args::list(const std::string& name) const {
  std::vector<std::string> out;
  std::stringstream s(text(name));
  for (std::string item; std::getline(s, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace appell::cli
