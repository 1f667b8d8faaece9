// Typed errors. Each maps to one exit code of the `fdem` CLI (see README "Exit codes"),
// so library code throws and only main() decides how the process ends.
#pragma once
#include <stdexcept>
#include <string>

namespace fdem {

// Bad input: case file, mesh, command line. Exit code 2. The message names the file,
// line, key, element or node at fault.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The run went numerically wrong: NaN, infinite value, inverted element, unstable step.
// Exit code 3.
struct NumericalError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// OpenCL trouble: no device, build failure, enqueue failure, out of device memory.
// Exit code 4.
struct DeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A kernel program failed to compile: carries the stage name and the build log.
struct BuildError : DeviceError {
  BuildError(const std::string& stage, const std::string& log)
      : DeviceError("OpenCL build of stage '" + stage + "' failed:\n" + log),
        stage_name(stage), build_log(log) {}
  std::string stage_name;
  std::string build_log;
};

// Writing output failed (disk full, permission, unwritable directory). Exit code 5.
// Frames already written stay readable.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace fdem
