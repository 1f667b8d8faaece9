// The fdem command line: exit codes and messages, run as a user would.
#include <doctest/doctest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>

#include "case_files.hpp"

namespace {

struct Result {
  int code = -1;
  std::string output;  // stdout and stderr together
};

// `environment`: assignments put before the command (e.g. "OMPI_COMM_WORLD_SIZE=3 ").
Result run_fdem(const std::string& args, const std::string& environment = "") {
  Result r;
  const char* env = std::getenv("FDEM_BINARY");  // overrides the build's, on another machine
  FILE* pipe = popen((fdem::test::child_environment() + environment + std::string(env && *env ? env : FDEM_BINARY) + " " + args + " 2>&1").c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
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

TEST_CASE("a numerical failure exits 3; a missing device exits 4") {
  fdem::test::TempDir dir;
  const auto r = run_fdem("run " + tiny_case(dir, "[[boundary]]\nregion = \"right\"\nvelocity = [-5000.0, 0.0]\n") +
                      " --set time.steps=5000");
  CHECK(r.code == 3);
  CHECK(has(r, "inverted"));
  const auto d = run_fdem("check " + tiny_case(dir) + " --device 7:7");
  CHECK(d.code == 0);  // check reports the device problem but the case itself is fine
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
}

}  // TEST_SUITE
