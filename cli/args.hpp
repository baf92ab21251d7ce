// A small command-line parser: positional arguments and --name value / --flag.
#pragma once

#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace appell::cli {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Args {
 public:
  /// `valued` options take a value, `flags` do not; anything else is an error.
  Args(int argc, char** argv, int first, const std::set<std::string>& valued,
       const std::set<std::string>& flags);

  const std::vector<std::string>& positional() const { return positional_; }
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string text(const std::string& name, const std::string& fallback = "") const;
  /// A finite number; throws UsageError naming the option otherwise.
  double number(const std::string& name, double fallback) const;
  double positiveNumber(const std::string& name, double fallback) const;
  /// A finite number ≥ 0 (a lower bound, where 0 means none).
  double nonNegativeNumber(const std::string& name) const;
  int integer(const std::string& name, int fallback) const;
  /// Comma-separated list.
  std::vector<std::string> list(const std::string& name) const;
  /// Every value of an option given more than once (--set a=1 --set b=2), in order.
  const std::vector<std::string>& all(const std::string& name) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;  ///< the last value of each option
  std::map<std::string, std::vector<std::string>> repeated_;
};

}  // namespace appell::cli
