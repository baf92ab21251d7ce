// Running a program from a test and reading what it printed: the CLI tests'
// one way to call `appell` (stdout and stderr together, and the exit status).
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace appell::test {

struct CommandResult {
  int status = -1;     ///< exit status (−1: did not exit normally or could not start)
  std::string output;  ///< stdout and stderr
};

inline CommandResult runCommand(const std::string& cmd) {
  CommandResult r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// `appell ARGS` from the build tree.
inline CommandResult runAppell(const std::string& args) {
  return runCommand(std::string(APPELL_BINARY_DIR) + "/cli/appell " + args);
}

}  // namespace appell::test
