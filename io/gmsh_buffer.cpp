#include "io/gmsh_buffer.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace fdem::io {

namespace fs = std::filesystem;

std::string read_file_bytes(const std::string& path, const char* what) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path + ": " + what + " not found");
  if (fs::is_directory(status)) throw InputError(path + ": is a directory, expected a " + what);
  // A FIFO would block and /dev/zero never ends: only regular files are read.
  if (!fs::is_regular_file(status)) throw InputError(path + ": is not a regular file, expected a " + what);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot open " + what + ": " + std::strerror(errno));
  std::ostringstream ss;
  ss << f.rdbuf();
  if (f.bad()) throw InputError(path + ": error reading " + what);
  return ss.str();
}

}  // namespace fdem::io
