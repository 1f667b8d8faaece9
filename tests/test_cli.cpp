// The fdem command line: exit codes and messages, run as a user would.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "case_files.hpp"
#include "fdem_cli.hpp"
#include "io/gmsh_reader.hpp"

namespace {

using Result = fdem::test::FdemResult;

// `environment`: assignments put before the command (e.g. "OMPI_COMM_WORLD_SIZE=3 ").
Result run_fdem(const std::string& args, const std::string& environment = "") {
  return fdem::test::run_fdem_cli(args, environment);
}

bool has(const Result& r, const std::string& text) { return r.output.find(text) != std::string::npos; }

// The bar on a 0.1 m mesh under gravity, held at its left end, for 50 steps.
std::string tiny_case(const fdem::test::TempDir& dir, const std::string& extra = "") {
  fdem::test::BarCase c;
  c.title = "tiny";
  c.mesh = "size = 0.1\n";
  c.time = "dt = \"auto\"\nsteps = 50\n";
  c.output = "dir = \"" + dir.str() + "/out\"\nframes = 2\n";
  c.rest = "[gravity]\ng = [0.0, -9.81]\n[[boundary]]\nregion = \"left\"\nfix = [\"x\", \"y\"]\n" + extra;
  return dir.write("tiny.toml", c.text());
}

}  // namespace

TEST_SUITE("cli") {

TEST_CASE("--version, devices, usage") {
  const auto v = run_fdem("--version");
  CHECK(v.code == 0);
  CHECK(has(v, "fdem 0."));
  const auto d = run_fdem("devices");
  CHECK(d.code == 0);
  CHECK(has(d, "fp64"));
  const auto u = run_fdem("frobnicate");
  CHECK(u.code == 2);
  CHECK(has(u, "unknown command 'frobnicate'"));
  CHECK(run_fdem("run").code == 2);
}

TEST_CASE("check prints counts, the stable step and the memory; run writes its files") {
  fdem::test::TempDir dir;
  const std::string path = tiny_case(dir);
  const auto c = run_fdem("check " + path);
  CHECK(c.code == 0);
  CHECK(has(c, "TRI3"));
  CHECK(has(c, "stable dt"));
  CHECK(has(c, "device memory needed"));
  CHECK(!has(c, "memory plan ("));
  // --memory: the plan array by array, then the total (the "device memory needed" figure).
  const auto m = run_fdem("check " + path + " --memory");
  CHECK(m.code == 0);
  CHECK(has(m, "memory plan ("));
  CHECK(has(m, "position"));
  CHECK(has(m, "B/TRI3"));
  const auto r = run_fdem("run " + path);
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(has(r, "ns per element-step"));
  CHECK(std::filesystem::exists(dir.str() + "/out/tiny.exo"));
  CHECK(std::filesystem::exists(dir.str() + "/out/tiny_history.nc"));
}

TEST_CASE("check --ranks prints the partition; a run started as one of several MPI ranks is refused") {
  fdem::test::TempDir dir;
  const std::string path = tiny_case(dir);
  const auto c = run_fdem("check " + path + " --ranks 2 --partition bisection");
  INFO(c.output);
  CHECK(c.code == 0);
  CHECK(has(c, "partition 2 ranks by bisection"));
  CHECK(has(c, "imbalance"));
  CHECK(run_fdem("check " + path + " --ranks 0").code == 2);
  CHECK(run_fdem("check " + path + " --ranks 2 --partition best").code == 2);
  CHECK(run_fdem("run " + path + " --ranks 2").code == 2);
  const auto launched = run_fdem("run " + path, "OMPI_COMM_WORLD_SIZE=3 ");
  CHECK(launched.code == 2);
  CHECK(has(launched, "one of 3 parallel ranks"));
  CHECK_FALSE(std::filesystem::exists(dir.str() + "/out/tiny.exo"));
  CHECK(run_fdem("run " + path + " --quiet", "OMPI_COMM_WORLD_SIZE=1 ").code == 0);  // one rank: runs
}

TEST_CASE("bad input exits 2 naming the file and the key") {
  fdem::test::TempDir dir;
  const auto typo = run_fdem("check " + tiny_case(dir, "[damping]\nlocall = 0.8\n"));
  CHECK(typo.code == 2);
  CHECK(has(typo, "did you mean 'local'"));
  const auto missing = run_fdem("check " + dir.str() + "/nothing.toml");
  CHECK(missing.code == 2);
  CHECK(has(missing, "nothing.toml"));
  const auto region = run_fdem("check " + tiny_case(dir, "[[boundary]]\nregion = \"rigth\"\nfix = [\"x\"]\n"));
  CHECK(region.code == 2);
  CHECK(has(region, "did you mean 'right'"));
  const auto set = run_fdem("check " + tiny_case(dir) + " --set time.dtt=1");
  CHECK(set.code == 2);
  CHECK(has(set, "did you mean 'dt'"));
}

TEST_CASE("each command has its own --help and refuses the options of the others") {
  for (const char* command : {"run", "check", "devices", "bench"}) {
    CAPTURE(command);
    const auto h = run_fdem(std::string(command) + " --help");
    CHECK(h.code == 0);
    CHECK(has(h, std::string("usage: fdem ") + command));
  }
  const auto run = run_fdem("run --help");
  CHECK(has(run, "--restart"));
  CHECK(has(run, "--max-triangles"));
  CHECK_FALSE(has(run, "--sizes"));
  CHECK_FALSE(has(run, "--memory"));
  CHECK(has(run_fdem("check -h"), "--memory"));
  CHECK(has(run_fdem("bench --help"), "--refine-rows"));
  const auto help_run = run_fdem("help run");
  CHECK(help_run.code == 0);
  CHECK(help_run.output == run.output);

  fdem::test::TempDir dir;
  const std::string path = tiny_case(dir);
  // Another command's option is refused, naming the option and the command, and nothing runs.
  const auto steps = run_fdem("run " + path + " --steps 5");
  CHECK(steps.code == 2);
  CHECK(has(steps, "fdem run does not take --steps (it belongs to fdem bench)"));
  CHECK_FALSE(std::filesystem::exists(dir.str() + "/out/tiny.exo"));
  const auto restart = run_fdem("check " + path + " --restart");
  CHECK(restart.code == 2);
  CHECK(has(restart, "fdem check does not take --restart (it belongs to fdem run)"));
  const auto memory = run_fdem("bench --memory");
  CHECK(memory.code == 2);
  CHECK(has(memory, "fdem bench does not take --memory (it belongs to fdem check)"));
  const auto devices = run_fdem("devices --device cpu");
  CHECK(devices.code == 2);
  CHECK(has(devices, "fdem devices does not take --device"));
  CHECK(run_fdem("devices extra").code == 2);
  const auto unknown = run_fdem("check " + path + " --frobnicate");
  CHECK(unknown.code == 2);
  CHECK(has(unknown, "fdem check: unknown option '--frobnicate'"));
  CHECK(run_fdem("run " + path + " --quiet=yes").code == 2);  // a switch takes no value
  CHECK(run_fdem("check " + path + " --set=time.steps=3").code == 0);  // --name=value is --name value
}

TEST_CASE("--quiet silences the progress lines of a run, not its summary") {
  fdem::test::TempDir dir;
  const std::string path = tiny_case(dir);
  const auto loud = run_fdem("run " + path);  // stderr is a pipe here: decile lines on stdout
  REQUIRE(loud.code == 0);
  CHECK(has(loud, "%  step"));
  const auto quiet = run_fdem("run " + path + " --quiet");
  INFO(quiet.output);
  REQUIRE(quiet.code == 0);
  CHECK_FALSE(has(quiet, "%  step"));
  CHECK(has(quiet, "done: 50 steps"));
}

TEST_CASE("a directory, a FIFO or a device given as the case is named as what it is") {
  fdem::test::TempDir dir;
  const auto directory = run_fdem("check " + dir.str());
  CHECK(directory.code == 2);
  CHECK(has(directory, dir.str() + ": is a directory, not a case file"));
  const auto zero = run_fdem("run /dev/zero");
  CHECK(zero.code == 2);
  CHECK(has(zero, "/dev/zero: is not a regular file (a character device), not a case file"));
  const std::string fifo = dir.str() + "/case.toml";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  const auto pipe = run_fdem("check " + fifo);  // would block in a reader that opened it
  CHECK(pipe.code == 2);
  CHECK(has(pipe, "is not a regular file (a FIFO)"));
  const auto restart = run_fdem("run " + tiny_case(dir) + " --restart " + dir.str());
  CHECK(restart.code == 2);
  CHECK(has(restart, "is a directory, not a checkpoint"));
}

TEST_CASE("meshing: a request for 10^12 triangles is refused at once; a limit can be raised" *
          doctest::skip(fdem::io::find_on_path("gmsh").empty())) {
  fdem::test::TempDir dir;
  const std::string geostatic = fdem::test::source_path("cases/geostatic/case.toml") + " --set output.dir=" + dir.str();
  const auto huge = run_fdem("check " + geostatic + " --set mesh.size=1e-4");
  INFO(huge.output);
  CHECK(huge.code == 2);
  CHECK(has(huge, "column.geo at size 0.0001: gmsh would make about 1.2e+12 triangles"));
  CHECK(has(huge, "raise the limit with --max-triangles N"));
  const auto lowered = run_fdem("check " + tiny_case(dir) + " --max-triangles 100");  // the bar at 0.1: ~50
  CHECK(lowered.code == 0);
  // (0.0195: not a size of the committed test meshes, which are read without meshing)
  const auto refused = run_fdem("check " + tiny_case(dir, "") + " --set mesh.size=0.0195 --max-triangles 100");
  CHECK(refused.code == 2);
  CHECK(has(refused, "above the limit of 100"));
  CHECK(run_fdem("check " + tiny_case(dir) + " --max-triangles 0").code == 2);
  CHECK(run_fdem("check " + tiny_case(dir) + " --max-triangles 1e6").code == 0);
}

TEST_CASE("a .geo file that runs programs is refused unless --allow-geo-programs") {
  fdem::test::TempDir dir;
  const std::string marker = dir.str() + "/marker";
  std::ifstream bar(fdem::test::source_path("tests/data/cases/bar.geo"));
  dir.write("bar_call.geo", std::string(std::istreambuf_iterator<char>(bar), {}) + "SystemCall \"touch " + marker + "\";\n");
  fdem::test::BarCase c;
  c.mesh = "size = 0.1\n";
  c.time = "steps = 5\ndt = \"auto\"\n";
  c.output = "dir = \"" + dir.str() + "/out\"\n";
  std::string text = c.text();
  text.replace(text.find(fdem::test::source_path("tests/data/cases/bar.geo")),
               fdem::test::source_path("tests/data/cases/bar.geo").size(), dir.str() + "/bar_call.geo");
  const std::string path = dir.write("call.toml", text);
  const auto refused = run_fdem("check " + path);
  INFO(refused.output);
  CHECK(refused.code == 2);
  CHECK(has(refused, "bar_call.geo: this .geo file would make gmsh run other programs"));
  CHECK(has(refused, "bar_call.geo:18: SystemCall"));
  CHECK_FALSE(std::filesystem::exists(marker));
  if (fdem::io::find_on_path("gmsh").empty()) return;
  CHECK(run_fdem("check " + path + " --allow-geo-programs").code == 0);
  CHECK(std::filesystem::exists(marker));
}

// The process ids whose parent is `parent` (from /proc).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string text((std::istreambuf_iterator<char>(stat)), {});
    const size_t close = text.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(text.substr(close + 2));
    char state = 0;
    long ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent) out.push_back(static_cast<pid_t>(std::stol(name)));
  }
  return out;
}

TEST_CASE("SIGTERM while gmsh meshes stops gmsh too, removes its files and ends fdem by the signal" *
          doctest::skip(fdem::io::find_on_path("gmsh").empty())) {
  fdem::test::TempDir dir;
  // The bar at 0.4 mm: about 1.4M triangles, tens of seconds of gmsh.
  const std::string path = tiny_case(dir);
  const std::string binary = [] {
    const char* env = std::getenv("FDEM_BINARY");
    return std::string(env && *env ? env : FDEM_BINARY);
  }();
  const std::string log = dir.str() + "/log.txt";
  const pid_t fdem_pid = ::fork();
  REQUIRE(fdem_pid >= 0);
  if (fdem_pid == 0) {
    fdem::test::restore_child_environment();
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(binary.c_str(), binary.c_str(), "check", path.c_str(), "--set", "mesh.size=4e-4", "--max-triangles", "1e9",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::vector<pid_t> gmsh;
  for (int k = 0; k < 100 && gmsh.empty(); ++k) {  // up to 10 s for fdem to start gmsh
    ::usleep(100'000);
    gmsh = children_of(fdem_pid);
  }
  REQUIRE(gmsh.size() == 1);
  ::usleep(300'000);  // into the meshing
  REQUIRE(::kill(fdem_pid, SIGTERM) == 0);
  int status = 0;
  REQUIRE(::waitpid(fdem_pid, &status, 0) == fdem_pid);
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), {});
  INFO(output);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGTERM);
  CHECK(output.find("meshing stopped by SIGTERM; gmsh was stopped and nothing was written") != std::string::npos);
  // gmsh is gone: no such process (it was waited for by fdem, not left to init).
  CHECK(::kill(gmsh[0], 0) == -1);
  CHECK(errno == ESRCH);
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir.path)) {
    CAPTURE(entry.path().string());
    CHECK(entry.path().string().find(".part") == std::string::npos);
  }
}

TEST_CASE("a numerical failure exits 3; a missing device exits 4") {
  fdem::test::TempDir dir;
  const auto r = run_fdem("run " + tiny_case(dir, "[[boundary]]\nregion = \"right\"\nvelocity = [-5000.0, 0.0]\n") +
                      " --set time.steps=5000");
  CHECK(r.code == 3);
  CHECK(has(r, "inverted"));
  const auto d = run_fdem("check " + tiny_case(dir) + " --device 7:7");
  CHECK(d.code == 4);  // as run (issue 28, row 12)
  CHECK(has(d, "no OpenCL device 7:7"));
  const auto run = run_fdem("run " + tiny_case(dir) + " --device 7:7");
  CHECK(run.code == 4);
}

TEST_CASE("bench prints a Table 2 row and its CSV") {
  fdem::test::TempDir dir;
  const auto r = run_fdem("bench --device cpu --sizes 3.0 --steps 2 --case " +
                          fdem::test::source_path("cases/ucs/case.toml") + " --csv " + dir.str() + "/bench.csv");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(has(r, "ms/step"));
  CHECK(has(r, "contact_forces"));
  CHECK(std::filesystem::exists(dir.str() + "/bench.csv"));
  CHECK(run_fdem("bench --sizes abc").code == 2);
  // --set reaches every row: the extrinsic model's rows have its two kernels.
  const auto x = run_fdem("bench --device cpu --sizes 3.0 --steps 2 --case " + fdem::test::source_path("cases/ucs/case.toml") +
                          " --set 'material.0.fracture.model=\"extrinsic\"'");
  INFO(x.output);
  CHECK(x.code == 0);
  CHECK(has(x, "every row with --set material.0.fracture.model=\"extrinsic\""));
  CHECK(has(x, "extrinsic_tie"));
  CHECK_FALSE(has(r, "extrinsic_tie"));
  const auto bad = run_fdem("bench --device cpu --sizes 3.0 --steps 2 --case " + fdem::test::source_path("cases/ucs/case.toml") +
                            " --set material.0.fracture.model=1");
  CHECK(bad.code == 2);
  CHECK(has(bad, "material[0].fracture.model must be a string"));
}

// Issue 28, rows 6, 11 and 12: what `check` accepted and `run` refused (or ran into).
namespace {

// The line of `r`'s output that starts with `prefix` ("" when none).
std::string line_of(const Result& r, const std::string& prefix) {
  const size_t at = r.output.find(prefix);
  return at == std::string::npos ? std::string() : r.output.substr(at, r.output.find('\n', at) - at);
}

}  // namespace

TEST_CASE("check refuses what run refuses: the device, the output folder, the output place, the checkpoint interval") {
  fdem::test::TempDir dir;
  const std::string path = tiny_case(dir);
  // A device that is not there: the same message and exit code.
  const auto check_device = run_fdem("check " + path + " --device 9:9");
  const auto run_device = run_fdem("run " + path + " --device 9:9");
  INFO(check_device.output);
  CHECK(check_device.code == 4);
  CHECK(run_device.code == 4);
  CHECK(!line_of(check_device, "device error: ").empty());
  CHECK(line_of(check_device, "device error: ") == line_of(run_device, "device error: "));
  // An output folder that cannot be made (a file stands where a folder would be).
  dir.write("plain_file", "not a folder\n");
  const std::string blocked = " --set output.dir=" + dir.str() + "/plain_file/out";
  const auto check_dir = run_fdem("check " + path + blocked);
  const auto run_dir = run_fdem("run " + path + blocked);
  INFO(check_dir.output);
  CHECK(check_dir.code == 5);
  CHECK(run_dir.code == 5);
  CHECK(has(check_dir, "output error: cannot create output directory '" + dir.str() + "/plain_file/out'"));
  CHECK(line_of(check_dir, "output error: ") == line_of(run_dir, "output error: "));
  // An output folder that exists and cannot be written (root writes anywhere).
  if (geteuid() != 0) {
    std::filesystem::create_directories(dir.str() + "/locked");
    std::filesystem::permissions(dir.str() + "/locked", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    const auto check_locked = run_fdem("check " + path + " --set output.dir=" + dir.str() + "/locked");
    const auto run_locked = run_fdem("run " + path + " --set output.dir=" + dir.str() + "/locked");
    CHECK(check_locked.code == 5);
    CHECK(has(check_locked, "cannot write in output directory"));
    CHECK(line_of(check_locked, "output error: ") == line_of(run_locked, "output error: "));
    std::filesystem::permissions(dir.str() + "/locked", std::filesystem::perms::owner_all);
  }
  // An output file name taken by a folder: refused before the run computes anything.
  std::filesystem::create_directories(dir.str() + "/out/tiny_history.nc");
  const auto check_taken = run_fdem("check " + path);
  const auto run_taken = run_fdem("run " + path);
  CHECK(check_taken.code == 5);
  CHECK(run_taken.code == 5);
  CHECK(has(check_taken, "tiny_history.nc' exists and is not a regular file"));
  CHECK_FALSE(std::filesystem::exists(dir.str() + "/out/tiny.exo"));
  std::filesystem::remove(dir.str() + "/out/tiny_history.nc");
  // The root of the file system or a system directory as output.dir (the mesh cache kept
  // out of them, should the check not hold).
  const std::string cache = "FDEM_MESH_CACHE=" + dir.str() + " ";
  for (const std::string place : {"/", "/etc", "/usr/share"}) {
    const auto r = run_fdem("check " + path + " --set output.dir=" + place, cache);
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(has(r, "output.dir = \"" + place + "\""));
  }
  CHECK(run_fdem("check " + path + " --set output.name=../escaped", cache).code == 2);
  // The chosen folder is reported.
  const auto fine = run_fdem("check " + path);
  CHECK(fine.code == 0);
  CHECK(has(fine, "output    " + dir.str() + "/out/ (tiny.exo, tiny_history.nc, tiny.ckpt)"));
  // A checkpoint interval below dt (row 6: the run looped for ever on it).
  const auto tiny_interval = run_fdem("check " + path + " --set output.checkpoint_every=1e-14");
  INFO(tiny_interval.output);
  CHECK(tiny_interval.code == 2);
  CHECK(has(tiny_interval, "output.checkpoint_every = 1e-14 s is shorter than the time step"));
}

}  // TEST_SUITE
