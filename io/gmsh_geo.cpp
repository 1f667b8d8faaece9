// Meshing of .geo files through the gmsh CLI, into a cache named by a hash of the .geo
// text and the element size.
#include "base/hash.hpp"
#include "io/gmsh_reader.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "base/errors.hpp"
#include "io/gmsh_buffer.hpp"

namespace fdem::io {

std::string find_on_path(const std::string& program) {
  namespace fs = std::filesystem;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) dir = ".";
    std::string candidate = dir + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) return candidate;
  }
  return {};
}

namespace {

namespace fs = std::filesystem;

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string last_lines(const std::string& text, int count) {
  size_t pos = text.size();
  while (pos > 0 && text[pos - 1] == '\n') --pos;
  size_t end = pos;
  for (int i = 0; i < count && pos > 0; ++i) {
    size_t nl = text.rfind('\n', pos - 1);
    pos = nl == std::string::npos ? 0 : nl;
  }
  return text.substr(pos == 0 ? 0 : pos + 1, end - (pos == 0 ? 0 : pos + 1));
}

}  // namespace

std::string mesh_geo(const std::string& geo_path, double size, const std::string& cache_dir) {
  const std::string geo_text = read_file_bytes(geo_path, ".geo file");
  char size_text[64];
  std::snprintf(size_text, sizeof size_text, "%.17g", size);
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a(geo_text + size_text)));
  const fs::path final_path = fs::path(cache_dir) / (fs::path(geo_path).stem().string() + "-" + hash + ".msh");
  std::error_code ec;
  if (fs::is_regular_file(final_path, ec)) return final_path.string();

  const std::string gmsh = find_on_path("gmsh");
  if (gmsh.empty())
    throw InputError(geo_path + ": cannot mesh: the gmsh program is not on PATH; install it (Debian/Ubuntu package 'gmsh': apt-get install gmsh) or give a .msh file");

  fs::create_directories(cache_dir, ec);
  if (ec) throw InputError(geo_path + ": cannot create mesh cache directory " + cache_dir + ": " + ec.message());
  // gmsh writes into a private name first; only a complete, checked mesh gets the
  // cache name, so an interrupted or failed run is never reused.
  const fs::path temp_path = final_path.string() + ".part" + std::to_string(::getpid()) + ".msh";
  std::string shown = "gmsh -2 " + shell_quote(geo_path) + " -format msh41 -o " + shell_quote(temp_path.string());
  if (size > 0) shown += std::string(" -setnumber size ") + size_text;
  const std::string command = shell_quote(gmsh) + shown.substr(4) + " </dev/null 2>&1";

  std::string output;
  int status = -1;
  if (FILE* pipe = ::popen(command.c_str(), "r")) {
    char buf[4096];
    size_t got;
    while ((got = std::fread(buf, 1, sizeof buf, pipe)) > 0) output.append(buf, got);
    status = ::pclose(pipe);
  }
  // gmsh 4.8 exits 1 on .geo errors but still writes what it parsed, so both the exit
  // status and "Error" lines count.
  const bool error_line = output.rfind("Error", 0) == 0 || output.find("\nError") != std::string::npos;
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || error_line || !fs::is_regular_file(temp_path, ec)) {
    fs::remove(temp_path, ec);
    throw InputError(geo_path + ": gmsh failed to mesh it (" + shown + "); gmsh said:\n" + last_lines(output, 12));
  }
  try {
    if (read_gmsh(temp_path.string()).triangles.empty()) throw InputError("no triangles");
  } catch (const InputError& e) {
    fs::remove(temp_path, ec);
    throw InputError(geo_path + ": gmsh ran but its mesh is unusable: " + e.what());
  }
  fs::rename(temp_path, final_path, ec);
  if (ec) {
    fs::remove(temp_path, ec);
    throw InputError(geo_path + ": cannot write mesh cache file " + final_path.string() + ": " + ec.message());
  }
  return final_path.string();
}

}  // namespace fdem::io
