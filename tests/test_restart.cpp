// Checkpoint and restart: a continued run gives the same bytes as one that never stopped,
// stops on signals and wall time with exit 75, and refuses checkpoints that do not fit.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "base/errors.hpp"
#include "case_files.hpp"
#include "engine/run/run.hpp"
#include "fixture.hpp"
#include "io/checkpoint_file.hpp"
#include <netcdf.h>

using namespace fdem;
namespace fs = std::filesystem;

namespace {

// A coarse Brazilian disc (contact with a skin, CE4s that break): every piece of state a
// restart must carry. Frames and rows on a fixed schedule (every, history_every), so runs
// of different lengths share it.
std::string disc_case(const test::TempDir& dir, const std::string& out, double end, const std::string& extra = "") {
  std::ifstream in(test::source_path("cases/brazilian/case.toml"));
  std::ostringstream text;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("frames", 0) == 0 || line.rfind("history_every", 0) == 0 || line.rfind("dir", 0) == 0 ||
        line.rfind("energy_limit", 0) == 0)
      continue;
    if (line.rfind("geo", 0) == 0) line = "geo = \"" + test::source_path("cases/brazilian/brazilian.geo") + "\"";
    if (line.rfind("size", 0) == 0) line = "size = 4e-3";
    if (line.rfind("end", 0) == 0) line = "end = " + std::to_string(end);
    // Platens 100 times faster than the case's: the disc cracks within the run.
    if (line.rfind("velocity", 0) == 0) line = line.find('-') != std::string::npos ? "velocity = [0.0, -2.5]" : "velocity = [0.0, 2.5]";
    text << line << "\n";
    if (line == "[output]")
      text << "dir = \"" << out << "\"\nevery = 5e-5\nhistory_every = 2e-6\nenergy_limit = 10.0\n" << extra;
  }
  return dir.write("disc.toml", text.str());
}

bool same_bytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
  return !sa.empty() && sa == sb;
}

std::string fdem_binary() {
  const char* env = std::getenv("FDEM_BINARY");
  return env && *env ? env : FDEM_BINARY;
}

// Starts `fdem run CASE ARGS...` as a child with its output in `log`; returns its pid.
pid_t start_fdem(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* f = freopen(log.c_str(), "w", stdout);
    (void)f;
    dup2(fileno(stdout), fileno(stderr));
    test::restore_child_environment();
    std::vector<char*> argv;
    std::string bin = fdem_binary();
    argv.push_back(bin.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(bin.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

// Waits (up to 60 s) until `path` exists.
bool wait_for(const std::string& path) {
  for (int k = 0; k < 6000; ++k) {
    if (fs::exists(path)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

std::string text_of(const std::string& path) {
  std::ifstream f(path);
  return std::string((std::istreambuf_iterator<char>(f)), {});
}

std::string refusal(const std::string& path, const std::string& restart, const std::vector<std::string>& set = {}) {
  try {
    test::run(path, set, test::restart_from(restart));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// The bar of tests/data/cases/bar.geo on a 0.1 m mesh under gravity (36 nodes, a few ms a
// run): a frame every 4 steps and a history row every step, `steps` steps.
std::string bar_case(const test::TempDir& dir, const std::string& out, int steps) {
  test::BarCase c;
  c.title = "bar";
  c.mesh = "size = 0.1\n";
  c.time = "dt = \"auto\"\nsteps = " + std::to_string(steps) + "\n";
  c.output = "dir = \"" + out + "\"\nevery = 4.9e-5\nhistory_every = 1.2e-5\n";
  c.rest = "[gravity]\ng = [0.0, -9.81]\n[[boundary]]\nregion = \"left\"\nfix = [\"x\", \"y\"]\n";
  return dir.write("bar.toml", c.text());
}

// Overwrites `count` bytes of `path` from `at` with zeros.
void zero_bytes(const std::string& path, size_t at, size_t count) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(at));
  const std::string zeros(count, '\0');
  f.write(zeros.data(), static_cast<std::streamsize>(zeros.size()));
}

std::string any_refusal(const std::string& path, const std::string& restart, const std::vector<std::string>& set = {}) {
  try {
    test::run(path, set, test::restart_from(restart));
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(accepted)";
}

bool has_partial_files(const std::string& dir) {
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".partial") return true;
  return false;
}

}  // namespace

TEST_SUITE("restart") {

TEST_CASE("a run to T and a run to T/2 restarted to T write the same bytes (history and every frame)") {
  test::TempDir dir;
  const std::string one = dir.str() + "/one", two = dir.str() + "/two";
  const auto whole = test::run(disc_case(dir, one, 2e-4));
  const auto half = test::run(disc_case(dir, two, 1e-4));
  const auto rest = test::run(disc_case(dir, two, 2e-4), {}, test::restart_from(two + "/brazilian.ckpt"));
  CHECK(rest.first_step == half.steps);
  CHECK(half.steps + rest.steps == whole.steps);
  CHECK(same_bytes(one + "/brazilian_history.nc", two + "/brazilian_history.nc"));
  CHECK(same_bytes(one + "/brazilian.exo", two + "/brazilian.exo"));
  CHECK(same_bytes(one + "/brazilian_fragments.nc", two + "/brazilian_fragments.nc"));
  CHECK(same_bytes(one + "/brazilian_events.nc", two + "/brazilian_events.nc"));  // the break catalogue
  CHECK(fs::exists(two + "/brazilian.ckpt.prev"));
  // The state really moved: contact was detected again and CE4s broke, before the
  // checkpoint and after it.
  const auto rebuilds = test::read_variable(one + "/brazilian_history.nc", "contact_rebuilds");
  const auto broken = test::read_variable(one + "/brazilian_history.nc", "broken_ce4");
  const size_t middle = rebuilds.size() / 2;
  MESSAGE("contact detections " << rebuilds[middle] << " then " << rebuilds.back() << ", broken CE4s " << broken[middle]
                                << " then " << broken.back());
  CHECK(rebuilds[middle] > 1);
  CHECK(rebuilds.back() > rebuilds[middle]);
  CHECK(broken.back() > broken[middle]);
}

TEST_CASE("a run killed with SIGKILL after a checkpoint, restarted, writes the same bytes as one never killed") {
  test::TempDir dir;
  const std::string one = dir.str() + "/one", two = dir.str() + "/two";
  test::run(disc_case(dir, one, 2e-4));
  const std::string path = disc_case(dir, two, 2e-4, "checkpoint_every = 3e-5\n");
  const pid_t pid = start_fdem({"run", path, "--quiet"}, dir.str() + "/killed.log");
  REQUIRE(wait_for(two + "/brazilian.ckpt.prev"));  // the second checkpoint is in place
  kill(pid, SIGKILL);
  CHECK(wait_exit(pid) == -SIGKILL);
  const auto before = io::read_checkpoint_file(two + "/brazilian.ckpt").integers.at("step");
  const auto rest = test::run(path, {}, test::restart_from(two + "/brazilian.ckpt"));
  MESSAGE("killed after the checkpoint at step " << before << "; the restart ran " << rest.steps << " steps");
  CHECK(rest.first_step == before);
  CHECK(same_bytes(one + "/brazilian_history.nc", two + "/brazilian_history.nc"));
  CHECK(same_bytes(one + "/brazilian.exo", two + "/brazilian.exo"));
  CHECK(same_bytes(one + "/brazilian_fragments.nc", two + "/brazilian_fragments.nc"));
  // Breaks the killed run recorded after its checkpoint are dropped, those after it are the same.
  CHECK(same_bytes(one + "/brazilian_events.nc", two + "/brazilian_events.nc"));
}

TEST_CASE("SIGTERM and --max-wall stop the run with exit 75, a checkpoint and the command that resumes it") {
  test::TempDir dir;
  const std::string out = dir.str() + "/out";
  const std::string path = disc_case(dir, out, 2e-3, "checkpoint_every = 2e-5\n");
  const pid_t pid = start_fdem({"run", path, "--quiet"}, dir.str() + "/term.log");
  REQUIRE(wait_for(out + "/brazilian.ckpt"));
  kill(pid, SIGTERM);
  CHECK(wait_exit(pid) == 75);
  const std::string log = text_of(dir.str() + "/term.log");
  CHECK(log.find("stopped by SIGTERM") != std::string::npos);
  CHECK(log.find("resume with: fdem run " + path + " --restart " + out + "/brazilian.ckpt") != std::string::npos);
  const auto at = io::read_checkpoint_file(out + "/brazilian.ckpt").integers.at("step");
  CHECK(at > 0);

  const pid_t wall = start_fdem({"run", path, "--quiet", "--restart", "--max-wall", "0.5"}, dir.str() + "/wall.log");
  CHECK(wait_exit(wall) == 75);
  const std::string wall_log = text_of(dir.str() + "/wall.log");
  CHECK(wall_log.find("resumed from " + out + "/brazilian.ckpt at step " + std::to_string(at)) != std::string::npos);
  CHECK(wall_log.find("stopped by --max-wall") != std::string::npos);
  CHECK(io::read_checkpoint_file(out + "/brazilian.ckpt").integers.at("step") > at);

  const pid_t check = start_fdem({"check", out + "/brazilian.ckpt"}, dir.str() + "/check.log");
  CHECK(wait_exit(check) == 0);
  const std::string check_log = text_of(dir.str() + "/check.log");
  for (const char* line : {"step", "time", "device", "precision     ", "broken CE4"})
    CHECK(check_log.find(std::string(line).substr(0, 9)) != std::string::npos);
}

TEST_CASE("checkpoints that do not fit are refused, naming the culprit (exit 2)") {
  test::TempDir dir;
  const std::string out = dir.str() + "/out";
  const std::string path = disc_case(dir, out, 5e-5);
  test::run(path);
  const std::string ckpt = out + "/brazilian.ckpt";
  const std::vector<std::string> longer = {"time.end=1e-4"};
  // A material value changed.
  const auto young = refusal(path, ckpt, {"time.end=1e-4", "material.0.young=20e9"});
  CHECK(young.find("material.0.young was 1.22e+10 in the checkpointed run and is 2e+10 now") !=
        std::string::npos);
  // Another mesh.
  const auto mesh = refusal(path, ckpt, {"time.end=1e-4", "mesh.size=5e-3"});
  CHECK(mesh.find("mesh.size was 0.004 in the checkpointed run and is 0.005 now") != std::string::npos);
  // Truncated and garbage files.
  const std::string cut = dir.str() + "/cut.ckpt", junk = dir.str() + "/junk.ckpt";
  {
    const std::string bytes = text_of(ckpt);
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    std::ofstream(junk, std::ios::binary) << "this is not a checkpoint\n";
  }
  const auto truncated = refusal(path, cut, longer);
  CHECK((truncated.find("cut short") != std::string::npos || truncated.find("truncated") != std::string::npos));
  CHECK(refusal(path, junk, longer).find("not a readable netCDF file") != std::string::npos);
  CHECK(refusal(path, dir.str() + "/none.ckpt", longer).find("no such file") != std::string::npos);
  // A checkpoint of the other precision.
  auto data = io::read_checkpoint_file(ckpt);
  data.text["precision"] = kDoublePrecision ? "float" : "double";
  io::write_checkpoint_file(dir.str() + "/other.ckpt", data);
  CHECK(refusal(path, dir.str() + "/other.ckpt", longer).find("-precision build") != std::string::npos);
  // Nothing left to run.
  CHECK(refusal(path, ckpt).find("extend the run with --set time.end") != std::string::npos);
  // The command line says exit 2.
  const pid_t pid = start_fdem({"run", path, "--restart", junk, "--set", "time.end=1e-4"}, dir.str() + "/junk.log");
  CHECK(wait_exit(pid) == 2);
  CHECK(text_of(dir.str() + "/junk.log").find("error: checkpoint '" + junk + "'") != std::string::npos);
}

// Issue 28, row 4: a restart copied what it could not read as frames and rows at t = 0.
TEST_CASE("a restart refuses an earlier Exodus file cut short or a history file zeroed in part, naming the record") {
  test::TempDir dir;
  const std::string out = dir.str() + "/out";
  const std::string path = bar_case(dir, out, 20);
  test::run(path);
  const std::string exo = out + "/bar.exo", history = out + "/bar_history.nc", ckpt = out + "/bar.ckpt";
  const std::string kept = dir.str() + "/kept";
  fs::copy(out, kept);
  const std::vector<std::string> longer = {"time.steps=40"};

  // The Exodus file cut to 60 %.
  fs::resize_file(exo, fs::file_size(exo) * 6 / 10);
  const std::string cut = text_of(exo);
  const auto truncated = any_refusal(path, ckpt, longer);
  INFO(truncated);
  CHECK(truncated.find("cannot continue '" + exo + "': frame ") != std::string::npos);
  CHECK(truncated.find("move it away") != std::string::npos);
  CHECK(text_of(exo) == cut);  // the earlier files are left as they were
  CHECK_FALSE(has_partial_files(out));
  const pid_t pid = start_fdem({"run", path, "--restart", "--set", "time.steps=40"}, dir.str() + "/cut.log");
  CHECK(wait_exit(pid) == 2);
  CHECK(text_of(dir.str() + "/cut.log").find("error: cannot continue '" + exo + "': frame ") != std::string::npos);

  // The history file with its last 30 % zeroed (rows: its header, the variables'
  // names and units, is the first half), the Exodus file whole again.
  fs::copy_file(kept + "/bar.exo", exo, fs::copy_options::overwrite_existing);
  const size_t size = fs::file_size(history);
  zero_bytes(history, size * 7 / 10, size - size * 7 / 10);
  const auto zeroed = any_refusal(path, ckpt, longer);
  INFO(zeroed);
  CHECK(zeroed.find("cannot continue '" + history + "': row ") != std::string::npos);
  CHECK(zeroed.find("is not the one the run wrote before its checkpoint") != std::string::npos);
  CHECK_FALSE(has_partial_files(out));

  // The way on: the damaged file moved away, the restart starts a new one at the
  // checkpoint's step and continues the Exodus file.
  fs::rename(history, dir.str() + "/damaged_history.nc");
  std::ostringstream said;
  RunOptions options = test::restart_from(ckpt);
  options.info = &said;
  const auto rest = test::run(prepare_case(path, longer), options);
  CHECK(rest.first_step == 20);
  CHECK(said.str().find("note: there is no earlier " + history + ": the new one starts at the checkpoint's step 20") !=
        std::string::npos);
  const auto times = test::read_variable(history, "time");
  const double dt = io::read_checkpoint_file(ckpt).numbers.at("dt");
  REQUIRE(!times.empty());
  CHECK(times.front() > 20.5 * dt);
  CHECK(test::read_variable(exo, "time_whole").size() == 11);  // frames at steps 0, 4, ..., 40
}

// Issue 28, row 5: the checkpoint's attributes were outside its checksum.
TEST_CASE("a checkpoint whose attributes were edited is refused, naming the attribute (exit 2)") {
  test::TempDir dir;
  const std::string out = dir.str() + "/out";
  const std::string path = bar_case(dir, out, 20);
  test::run(path);
  const std::string ckpt = out + "/bar.ckpt";
  const std::string edited = dir.str() + "/edited.ckpt", added = dir.str() + "/added.ckpt";
  fs::copy_file(ckpt, edited);
  fs::copy_file(ckpt, added);
  {
    int nc = -1;
    REQUIRE(nc_open(edited.c_str(), NC_WRITE, &nc) == NC_NOERR);
    const long long step = 5;
    REQUIRE(nc_redef(nc) == NC_NOERR);
    REQUIRE(nc_put_att_longlong(nc, NC_GLOBAL, "step", NC_INT64, 1, &step) == NC_NOERR);
    REQUIRE(nc_close(nc) == NC_NOERR);
    REQUIRE(nc_open(added.c_str(), NC_WRITE, &nc) == NC_NOERR);
    REQUIRE(nc_redef(nc) == NC_NOERR);
    const std::string note = "ncatted -a ... (a tool's note)";
    REQUIRE(nc_put_att_text(nc, NC_GLOBAL, "history", note.size(), note.c_str()) == NC_NOERR);
    REQUIRE(nc_close(nc) == NC_NOERR);
  }
  const auto step = refusal(path, edited, {"time.steps=40"});
  INFO(step);
  CHECK(step.find("checkpoint '" + edited + "': attribute 'step' does not match its checksum") != std::string::npos);
  const auto history = refusal(path, added, {"time.steps=40"});
  INFO(history);
  CHECK(history.find("checkpoint '" + added + "': attribute 'history'") != std::string::npos);
  const pid_t run = start_fdem({"run", path, "--restart", edited, "--set", "time.steps=40"}, dir.str() + "/run.log");
  CHECK(wait_exit(run) == 2);
  const pid_t check = start_fdem({"check", edited}, dir.str() + "/check.log");
  CHECK(wait_exit(check) == 2);
  CHECK(text_of(dir.str() + "/check.log").find("attribute 'step'") != std::string::npos);
  // The file as written passes; `check` says what the output files held at it, and takes
  // the one kept before it too.
  CHECK(io::read_checkpoint_file(ckpt).integers.at("step") == 20);
  fs::copy_file(ckpt, dir.str() + "/bar.ckpt.prev");
  const pid_t good = start_fdem({"check", dir.str() + "/bar.ckpt.prev"}, dir.str() + "/good.log");
  CHECK(wait_exit(good) == 0);
  CHECK(text_of(dir.str() + "/good.log").find("output     6 frames, 20 history rows") != std::string::npos);
}

// Issue 28, row 12: a run that failed before its first frame left empty files over the
// earlier run's.
TEST_CASE("a run that fails before its first frame leaves the earlier run's files as they were") {
  test::TempDir dir;
  const std::string out = dir.str() + "/out";
  const std::string path = bar_case(dir, out, 20);
  test::run(path);
  const std::string exo = out + "/bar.exo", history = out + "/bar_history.nc";
  const std::string exo_bytes = text_of(exo), history_bytes = text_of(history);
  // The history file's temporary name taken by a device: the history file cannot be
  // made after the Exodus file was.
  fs::create_symlink("/dev/full", history + ".partial");
  std::string why;
  try {
    test::run(path);
  } catch (const OutputError& e) {
    why = e.what();
  }
  INFO(why);
  CHECK(why.find("exists and is not a regular file") != std::string::npos);
  CHECK(text_of(exo) == exo_bytes);
  CHECK(text_of(history) == history_bytes);
  CHECK_FALSE(fs::exists(exo + ".partial"));
  fs::remove(history + ".partial");
  // A run that goes through puts its files in place.
  test::run(path, {"time.steps=24"});
  CHECK(test::read_variable(exo, "time_whole").size() == 7);
  CHECK_FALSE(has_partial_files(out));
}

// Issue 28, row 6: signals are honoured in every loop that can run long, the restart's
// copy of the earlier files included.
TEST_CASE("a signal while a restart copies the earlier files stops it, the files and checkpoint as they were") {
  test::TempDir dir;
  const std::string out = dir.str() + "/out";
  const std::string path = bar_case(dir, out, 20);
  test::run(path);
  const std::string exo = out + "/bar.exo", history = out + "/bar_history.nc", ckpt = out + "/bar.ckpt";
  const std::string exo_bytes = text_of(exo), history_bytes = text_of(history), ckpt_bytes = text_of(ckpt);
  volatile std::sig_atomic_t stop = SIGTERM;  // arrived before the copy's first record
  RunOptions options = test::restart_from(ckpt);
  options.stop = &stop;
  const auto s = test::run(prepare_case(path, {"time.steps=40"}), options);
  CHECK(s.interrupted);
  CHECK(s.stop_reason == "SIGTERM");
  CHECK(s.steps == 0);
  CHECK(s.checkpoint == ckpt);
  CHECK(text_of(exo) == exo_bytes);
  CHECK(text_of(history) == history_bytes);
  CHECK(text_of(ckpt) == ckpt_bytes);
  CHECK_FALSE(has_partial_files(out));
}

TEST_CASE("checkpoints whose netCDF header claims more than the file holds are refused before libnetcdf opens them") {
  // The fuzzer's finds (docs/fuzzing.md): a negative-size memcpy in nc_open (abort), an
  // 8 GB attribute, an array of 1.3e17 bytes. Each must be an InputError naming the file.
  for (const char* name : {"netcdf-negative-memcpy.ckpt", "oom-attr-8gb.ckpt", "huge-array-dims.ckpt"}) {
    CAPTURE(name);
    const std::string path = test::source_path(std::string("tests/fuzz/regressions/checkpoint/") + name);
    try {
      io::read_checkpoint_file(path);
      FAIL("read without an error");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find(name) != std::string::npos);
    }
  }
}

}
