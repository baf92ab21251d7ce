// An environment variable set for a test's duration (as sourcing a ROS
// workspace's setup script sets ROS_PACKAGE_PATH or AMENT_PREFIX_PATH), then
// restored to what the caller had: a later test may read the caller's value.
#pragma once

#include <cstdlib>
#include <optional>
#include <string>

namespace appell::test {

struct ScopedEnv {
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) ::setenv(name_, old_->c_str(), 1);
    else ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace appell::test
