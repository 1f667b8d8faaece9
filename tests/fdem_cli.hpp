// The fdem program run as a child by the tests (FDEM_BINARY: the test binary's build
// define, or the environment's on another machine).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "case_files.hpp"

namespace fdem::test {

// `fdem ARGS` run as a child through the shell: its exit code (-1 when it did not exit) and
// its stdout and stderr together. FDEM_BINARY in the environment overrides the build's
// (on another machine); `environment`: assignments put before the command (e.g.
// "OMPI_COMM_WORLD_SIZE=3 ").
struct FdemResult {
  int code = -1;
  std::string output;
};
inline FdemResult run_fdem_cli(const std::string& args, const std::string& environment = "") {
  FdemResult r;
  const char* env = std::getenv("FDEM_BINARY");
  FILE* pipe = popen((child_environment() + environment + std::string(env && *env ? env : FDEM_BINARY) + " " + args +
                      " 2>&1").c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot start fdem " + args);
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace fdem::test
