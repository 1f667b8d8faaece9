// Meshing of .geo files through the gmsh CLI, into a cache named by a hash of the .geo
// text and the element size: the program check, the triangle-count estimate and the
// limit, progress, and stopping gmsh on a signal.
#include "base/hash.hpp"
#include "io/gmsh_reader.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>
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

GeoMeshing& geo_meshing() {
  static GeoMeshing options = [] {
    GeoMeshing o;
    o.progress = &std::cerr;
    return o;
  }();
  return options;
}

namespace {

namespace fs = std::filesystem;

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

std::string format_count(double n) {
  char buf[64];
  if (n < 1e7)
    std::snprintf(buf, sizeof buf, "%.0f", n);
  else
    std::snprintf(buf, sizeof buf, "%.2g", n);
  return buf;
}

// ---- the program check ---------------------------------------------------------------

std::string lower_extension(const std::string& name) {
  std::string ext = fs::path(name).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// Files that gmsh parses as .geo text (scanned in turn) or reads as data. Anything else
// named in Include/Merge may be run: gmsh 4.8 runs a merged .py file with Python, and
// treats other executables as ONELAB clients.
bool parsed_as_geo(const std::string& ext) { return ext == ".geo" || ext == ".geo_unrolled" || ext == ".opt"; }
bool data_file(const std::string& ext) {
  static const std::set<std::string> kData = {".msh", ".step", ".stp", ".brep", ".iges", ".igs", ".stl", ".pos",
                                              ".med", ".unv", ".vtk", ".bdf", ".nas", ".mesh", ".x_t", ".xao",
                                              ".ply", ".ply2", ".off", ".obj", ".inp", ".su2", ".dat", ".txt"};
  return kData.count(ext) > 0;
}

void scan_geo(const std::string& path, std::set<std::string>& seen, std::vector<std::string>& found, int depth) {
  std::error_code ec;
  const std::string key = fs::weakly_canonical(path, ec).string();
  if (!seen.insert(key.empty() ? path : key).second || depth > 20) return;
  const std::string text = read_file_bytes(path, ".geo file");
  int line = 1;
  std::string pending;  // "Include" or "Merge…" waiting for its file-name argument
  int pending_line = 0;
  auto finish_pending = [&](const std::string* literal) {
    if (pending.empty()) return;
    const std::string where = path + ":" + std::to_string(pending_line) + ": ";
    if (!literal) {
      found.push_back(where + pending + " of a file whose name is computed (it cannot be checked)");
    } else {
      const fs::path target = fs::path(*literal).is_absolute() ? fs::path(*literal) : fs::path(path).parent_path() / *literal;
      const std::string ext = lower_extension(*literal);
      if (parsed_as_geo(ext) || pending == "Include") {
        if (fs::is_regular_file(target, ec)) scan_geo(target.string(), seen, found, depth + 1);
      } else if (!data_file(ext)) {
        found.push_back(where + pending + " \"" + *literal + "\" (gmsh runs .py files and other programs it merges)");
      }
    }
    pending.clear();
  };
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      i += 2;
      while (i < text.size() && !(text[i] == '*' && i + 1 < text.size() && text[i + 1] == '/')) line += text[i++] == '\n';
      i += 2;
    } else if (c == '"') {
      std::string literal;
      for (++i; i < text.size() && text[i] != '"'; ++i) {
        if (text[i] == '\\' && i + 1 < text.size()) ++i;
        if (text[i] == '\n') ++line;
        literal += text[i];
      }
      ++i;
      finish_pending(&literal);
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const size_t start = i;
      while (i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_')) ++i;
      const std::string word = text.substr(start, i - start);
      finish_pending(nullptr);
      if (word == "System" || word == "SystemCall" || word == "NonBlockingSystemCall" || word == "OnelabRun") {
        found.push_back(path + ":" + std::to_string(line) + ": " + word + " (runs a program)");
      } else if (word == "Include" || word == "Merge" || word == "MergeWithBoundingBox") {
        pending = word;
        pending_line = line;
      }
    } else {
      if (!std::isspace(static_cast<unsigned char>(c)) && c != '(') finish_pending(nullptr);
      ++i;
    }
  }
  finish_pending(nullptr);
}

// ---- running gmsh --------------------------------------------------------------------

volatile std::sig_atomic_t g_meshing_signal = 0;

std::string signal_name(int signal) {
  switch (signal) {
    case SIGTERM: return "SIGTERM";
    case SIGINT: return "SIGINT";
    case SIGHUP: return "SIGHUP";
    case SIGUSR1: return "SIGUSR1";
    default: return "signal " + std::to_string(signal);
  }
}
extern "C" void meshing_signal_handler(int signal) { g_meshing_signal = signal; }

// Catches the stop signals for as long as gmsh runs, then puts the previous handlers
// back (fdem's own run loop installs its handlers later).
class SignalGuard {
 public:
  SignalGuard() {
    g_meshing_signal = 0;
    struct sigaction action {};
    action.sa_handler = meshing_signal_handler;
    sigemptyset(&action.sa_mask);
    for (size_t k = 0; k < std::size(kSignals); ++k) ::sigaction(kSignals[k], &action, &old_[k]);
  }
  ~SignalGuard() {
    for (size_t k = 0; k < std::size(kSignals); ++k) ::sigaction(kSignals[k], &old_[k], nullptr);
  }
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  static constexpr int kSignals[] = {SIGTERM, SIGINT, SIGHUP, SIGUSR1};
  struct sigaction old_[std::size(kSignals)] {};
};

// A path that goes inside a string of the .geo language.
void check_geo_string(const std::string& geo_path, const std::string& path) {
  for (char c : path)
    if (c == '"' || c == '\\' || static_cast<unsigned char>(c) < 0x20)
      throw InputError(geo_path + ": cannot mesh: the path '" + path +
                       "' holds a double quote, backslash or control character, which a gmsh script cannot name");
}

// The script gmsh runs: the user's .geo, then coarse meshes at Mesh.MeshSizeFactor
// 1e12, 1e12/3, 1e12/9, … (every size scaled, fields and clamps included) until one has
// 2,000 triangles or the factor reaches 1. Such a mesh has N ∝ factor^-2, so the count at
// factor 1 is N × factor²; a mesh that grew less than 3^1.5 times for the last step
// does not scale so (Transfinite, Layers) and the measured exponent is used instead.
// Above fdem_max_triangles it stops; else it meshes at the .geo's own factor and saves.
std::string driver_script(const std::string& geo_abs, const std::string& out_path, int algorithm, const std::string& extra) {
  return "Include \"" + geo_abs + "\";\n" + extra +
         (algorithm > 0 ? "Mesh.Algorithm = " + std::to_string(algorithm) + ";\n" : std::string()) +
         R"(fdem_user_factor = Mesh.MeshSizeFactor;
fdem_verbosity = General.Verbosity;
If (fdem_verbosity > 1) General.Verbosity = 1; EndIf  // errors only from the coarse meshes)" "\n" R"(
fdem_f = 1e12; fdem_done = 0; fdem_last = 1; fdem_n = 0; fdem_prev_n = 0;
For fdem_k In {1:40}
  If (fdem_done == 0)
    If (fdem_f < 1) fdem_f = 1; EndIf
    Mesh.MeshSizeFactor = fdem_user_factor * fdem_f;
    Delete Meshes;
    Mesh 2;
    fdem_prev_n = fdem_n;
    fdem_n = Mesh.NbTriangles;
    fdem_last = fdem_f;
    If ((fdem_n >= 2000 && fdem_k >= 2) || fdem_f == 1) fdem_done = 1; EndIf
    fdem_f = fdem_f / 3;
  EndIf
EndFor
fdem_p = 2;
If (fdem_last > 1 && fdem_prev_n > 0 && fdem_n < 5.196 * fdem_prev_n)
  fdem_p = Log(fdem_n / fdem_prev_n) / Log(3);
  If (fdem_p < 0) fdem_p = 0; EndIf
EndIf
fdem_estimate = fdem_n * fdem_last ^ fdem_p;
General.Verbosity = 3;  // the least at which gmsh prints Printf's text
Printf("fdem-estimate %.17g", fdem_estimate);
General.Verbosity = fdem_verbosity;
If (fdem_estimate <= fdem_max_triangles)
  If (fdem_last != 1)
    Mesh.MeshSizeFactor = fdem_user_factor;
    Delete Meshes;
    Mesh 2;
  EndIf
  Mesh.MshFileVersion = 4.1;
  Save ")" + out_path + "\";\nEndIf\n";
}

struct GmshRun {
  std::string output;   // stdout and stderr, the fdem- lines included
  int status = -1;      // waitpid status
  double estimate = -1; // from the fdem-estimate line; < 0 when gmsh printed none
};

// Runs gmsh in its own process group (so that stopping it stops what it started too)
// with output to a pipe, relaying progress; on a stop signal kills the group and throws.
GmshRun run_gmsh(const std::vector<std::string>& args, const std::string& geo_path, const GeoMeshing& options,
                 const std::vector<fs::path>& temporaries) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw InputError(geo_path + ": cannot run gmsh: pipe: " + std::strerror(errno));
  const int dev_null = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  const pid_t parent = ::getpid();
  SignalGuard guard;
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    if (dev_null >= 0) ::close(dev_null);
    throw InputError(geo_path + ": cannot run gmsh: fork: " + std::strerror(errno));
  }
  if (pid == 0) {
    // The child: async-signal-safe calls only until exec. gmsh dies with fdem (even
    // on SIGKILL) through the parent-death signal.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int s : {SIGTERM, SIGINT, SIGHUP, SIGUSR1}) ::sigaction(s, &dfl, nullptr);
    if (dev_null >= 0) ::dup2(dev_null, 0);
    ::dup2(fds[1], 1);
    ::dup2(fds[1], 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here, so that the group exists before any kill below
  ::close(fds[1]);
  if (dev_null >= 0) ::close(dev_null);

  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto next_progress = start + std::chrono::duration<double>(options.progress_every);
  GmshRun run;
  std::string pending_line, last_info;
  bool open = true, exited = false;
  while (open) {
    if (g_meshing_signal) {
      const int signal = g_meshing_signal;
      ::kill(-pid, SIGTERM);
      int status = 0;
      bool gone = false;
      for (int k = 0; k < 40 && !gone; ++k) {  // 2 s for gmsh to go, then SIGKILL
        gone = ::waitpid(pid, &status, WNOHANG) == pid;
        if (!gone) ::usleep(50'000);
      }
      ::kill(-pid, SIGKILL);
      if (!gone) ::waitpid(pid, &status, 0);
      ::close(fds[0]);
      std::error_code ec;
      for (const auto& t : temporaries) fs::remove(t, ec);
      throw MeshingStopped(signal, geo_path + ": meshing stopped by " + signal_name(signal) +
                                       "; gmsh was stopped and nothing was written");
    }
    struct pollfd p {fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, 200);
    // gmsh gone but the pipe still open: a program it started in the background holds
    // it (NonBlockingSystemCall, allowed by --allow-geo-programs); stop reading.
    if (ready == 0 && !exited && ::waitpid(pid, &run.status, WNOHANG) == pid) exited = true;
    if (ready == 0 && exited) break;
    if (ready > 0) {
      char buf[4096];
      const ssize_t got = ::read(fds[0], buf, sizeof buf);
      if (got > 0) {
        pending_line.append(buf, static_cast<size_t>(got));
        size_t nl;
        while ((nl = pending_line.find('\n')) != std::string::npos) {
          const std::string line = pending_line.substr(0, nl);
          pending_line.erase(0, nl + 1);
          if (line.rfind("fdem-estimate ", 0) == 0) {
            run.estimate = std::strtod(line.c_str() + 14, nullptr);
            continue;
          }
          if (!line.empty()) last_info = line.rfind("Info    : ", 0) == 0 ? line.substr(10) : line;
          // Enough of gmsh's log for an error message, not the whole of a long run.
          if (run.output.size() < (1u << 20)) run.output += line + "\n";
          else run.output = last_lines(run.output, 40) + "\n" + line + "\n";
        }
      } else if (got == 0 || (errno != EINTR && errno != EAGAIN)) {
        open = false;
      }
    }
    if (options.progress && options.progress_every > 0 && clock::now() >= next_progress) {
      const double seconds = std::chrono::duration<double>(clock::now() - start).count();
      char elapsed[32];
      std::snprintf(elapsed, sizeof elapsed, "%.0f s", seconds);
      *options.progress << "meshing " << geo_path << " with gmsh, " << elapsed
                        << (run.estimate >= 0 ? ", about " + format_count(run.estimate) + " triangles" : std::string())
                        << ": " << last_info << std::endl;
      next_progress = clock::now() + std::chrono::duration<double>(options.progress_every);
    }
  }
  ::close(fds[0]);
  if (!pending_line.empty()) run.output += pending_line;
  while (!exited && ::waitpid(pid, &run.status, 0) < 0 && errno == EINTR) {
    if (g_meshing_signal) ::kill(-pid, SIGKILL);
  }
  if (g_meshing_signal) {
    std::error_code ec;
    for (const auto& t : temporaries) fs::remove(t, ec);
    throw MeshingStopped(g_meshing_signal, geo_path + ": meshing stopped by " + signal_name(g_meshing_signal) +
                                               "; gmsh was stopped and nothing was written");
  }
  return run;
}

// FDEM_MESH_RECORD=FILE (a developer's aid, tools/gpu-suite --refresh-meshes): one line
// per mesh returned, "NAME<TAB>SIZE<TAB>GEO", so that a run of the test suite lists the
// meshes it needs and what they were made from; a fourth field holds what the cache name
// hashes beside the .geo and the size (the algorithm, text appended to the .geo such as
// embedded joints), with \, newline and tab written \\, \n and \t.
void record_mesh(const std::string& cache_name, const std::string& size_text, const std::string& geo_path,
                 const std::string& suffix) {
  const char* record = std::getenv("FDEM_MESH_RECORD");
  if (!record || !*record) return;
  std::string escaped;
  for (const char c : suffix) escaped += c == '\\' ? "\\\\" : c == '\n' ? "\\n" : c == '\t' ? "\\t" : std::string(1, c);
  std::error_code ec;
  std::ofstream out(record, std::ios::app);
  out << cache_name << "\t" << size_text << "\t" << fs::absolute(geo_path, ec).string();
  if (!escaped.empty()) out << "\t" << escaped;
  out << "\n";
}

}  // namespace

std::vector<std::string> geo_program_commands(const std::string& geo_path) {
  std::set<std::string> seen;
  std::vector<std::string> found;
  scan_geo(geo_path, seen, found, 0);
  return found;
}

std::string mesh_geo(const std::string& geo_path, double size, const std::string& cache_dir) {
  return mesh_geo(geo_path, size, cache_dir, geo_meshing());
}

int gmsh_algorithm_number(const std::string& algorithm) {
  if (algorithm.empty()) return 0;
  if (algorithm == "meshadapt") return 1;
  if (algorithm == "delaunay") return 5;
  if (algorithm == "frontal-delaunay") return 6;
  throw InputError("mesh.algorithm = \"" + algorithm + "\" is not valid (allowed: \"frontal-delaunay\", \"delaunay\", \"meshadapt\")");
}

std::string mesh_geo(const std::string& geo_path, double size, const std::string& cache_dir, const GeoMeshing& options) {
  return mesh_geo(geo_path, size, "", cache_dir, options);
}

std::string mesh_geo(const std::string& geo_path, double size, const std::string& algorithm,
                     const std::string& cache_dir, const GeoMeshing& options, const std::string& extra) {
  const int algorithm_number = gmsh_algorithm_number(algorithm);
  const std::string geo_text = read_file_bytes(geo_path, ".geo file");
  if (!options.allow_programs) {
    const auto programs = geo_program_commands(geo_path);
    if (!programs.empty()) {
      std::string list;
      for (const auto& p : programs) list += "\n  " + p;
      throw InputError(geo_path + ": this .geo file would make gmsh run other programs:" + list +
                       "\nA .geo file is a program; read it, and if you trust it pass --allow-geo-programs to fdem "
                       "run/check (or mesh it yourself and give the .msh as mesh.file)");
    }
  }
  char size_text[64];
  std::snprintf(size_text, sizeof size_text, "%.17g", size);
  // The size as the user wrote it (the shortest text that reads back the same).
  char size_shown[64];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(size_shown, sizeof size_shown, "%.*g", digits, size);
    if (std::strtod(size_shown, nullptr) == size) break;
  }
  char hash[17];
  // What the name hashes beside the .geo and the size (FDEM_MESH_RECORD's fourth field).
  const std::string suffix = (algorithm.empty() ? std::string() : "\nMesh.Algorithm=" + algorithm) +
                             (extra.empty() ? std::string() : "\nextra:\n" + extra);
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a(geo_text + size_text + suffix)));
  const std::string cache_name = fs::path(geo_path).stem().string() + "-" + hash + ".msh";
  const fs::path final_path = fs::path(cache_dir) / cache_name;
  std::error_code ec;
  if (fs::is_regular_file(final_path, ec)) {
    record_mesh(cache_name, size_text, geo_path, suffix);
    return final_path.string();
  }
  // Read-only caches (the committed test meshes): looked up, never written.
  if (const char* readonly = std::getenv("FDEM_MESH_CACHE_RO")) {
    std::stringstream dirs(readonly);
    std::string dir;
    while (std::getline(dirs, dir, ':'))
      if (!dir.empty() && fs::is_regular_file(fs::path(dir) / cache_name, ec)) {
        record_mesh(cache_name, size_text, geo_path, suffix);
        return (fs::path(dir) / cache_name).string();
      }
  }

  const std::string gmsh = find_on_path("gmsh");
  if (gmsh.empty())
    throw InputError(geo_path + ": cannot mesh: the gmsh program is not on PATH; install it (Debian/Ubuntu package 'gmsh': apt-get install gmsh) or give a .msh file");

  fs::create_directories(cache_dir, ec);
  if (ec) throw InputError(geo_path + ": cannot create mesh cache directory " + cache_dir + ": " + ec.message());
  // gmsh writes into a private name first; only a complete, checked mesh gets the
  // cache name, so an interrupted or failed run is never reused.
  const std::string part = final_path.string() + ".part" + std::to_string(::getpid());
  const fs::path temp_path = part + ".msh", driver_path = part + ".geo";
  const std::string geo_abs = fs::absolute(geo_path, ec).string();
  // gmsh resolves the script's Save path against the script's own folder, so a relative
  // cache folder (output.dir = "out/...") would put the mesh in out/.../out/...: absolute.
  const std::string temp_abs = fs::absolute(temp_path, ec).string();
  check_geo_string(geo_path, geo_abs);
  check_geo_string(geo_path, temp_abs);
  {
    std::ofstream driver(driver_path);
    driver << driver_script(geo_abs, temp_abs, algorithm_number, extra);
    if (!driver) throw InputError(geo_path + ": cannot write " + driver_path.string() + " in the mesh cache");
  }
  // What a user would type to see gmsh's own messages.
  std::string shown = "gmsh -2 " + geo_path;
  if (size > 0) shown += std::string(" -setnumber size ") + size_shown;
  if (algorithm_number > 0)
    shown += std::string(" -algo ") + (algorithm_number == 1 ? "meshadapt" : algorithm_number == 5 ? "del2d" : "front2d");
  char limit_text[32];
  std::snprintf(limit_text, sizeof limit_text, "%ld", options.max_triangles);
  std::vector<std::string> args = {gmsh, driver_path.string(), "-setnumber", "fdem_max_triangles", limit_text};
  if (size > 0) args.insert(args.end(), {"-setnumber", "size", size_text});
  args.push_back("-");  // parse the script (which meshes and saves), then exit

  GmshRun run;
  try {
    run = run_gmsh(args, geo_path, options, {temp_path, driver_path});
  } catch (...) {
    fs::remove(driver_path, ec);
    fs::remove(temp_path, ec);
    throw;
  }
  fs::remove(driver_path, ec);
  const std::string& output = run.output;
  if (run.estimate > static_cast<double>(options.max_triangles)) {
    fs::remove(temp_path, ec);
    throw InputError(geo_path + (size > 0 ? std::string(" at size ") + size_shown : std::string()) +
                     ": gmsh would make about " + format_count(run.estimate) +
                     " triangles (estimated from coarser meshes of the same .geo), above the limit of " +
                     std::to_string(options.max_triangles) +
                     "; give a larger size (mesh.size), or raise the limit with --max-triangles N");
  }
  // gmsh 4.8 exits 1 on .geo errors but still writes what it parsed, so both the exit
  // status and "Error" lines count.
  const bool error_line = output.rfind("Error", 0) == 0 || output.find("\nError") != std::string::npos;
  const int status = run.status;
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || error_line || !fs::is_regular_file(temp_path, ec)) {
    fs::remove(temp_path, ec);
    // gmsh's errors first (a long log would push them out of its last lines).
    std::string errors;
    std::istringstream lines(output);
    std::string line;
    int count = 0;
    while (std::getline(lines, line))
      if (line.rfind("Error", 0) == 0 && ++count <= 12) errors += line + "\n";
    throw InputError(geo_path + ": gmsh failed to mesh it (" + shown + "); gmsh said:\n" +
                     (errors.empty() ? last_lines(output, 12) : errors + last_lines(output, 3)));
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
  record_mesh(cache_name, size_text, geo_path, suffix);
  return final_path.string();
}

}  // namespace fdem::io
