// Excavation ([[excavation]]): a region's forces ramped to zero, its triangles marked in
// the frames, the strain energy they carry out accounted (excavated_energy), restarts
// across the ramp bitwise, and bad entries refused with the file and the key. The check
// is cases/tunnel-kirsch on a coarse mesh (tests/data/cases/tunnel_small.msh: its
// tunnel.geo at size 4: 0.08 m elements at the wall, 6.4 m at the edges): the hoop stress at the wall within
// 10% of Kirsch's at 0° and 90° (the case's own mesh: within 3%, validation/runs.cpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>

#include "base/errors.hpp"
#include "case_files.hpp"
#include "fdem_cli.hpp"
#include "engine/model/model.hpp"
#include "engine/run/prepare_case.hpp"
#include "fixture.hpp"
#include "kirsch_measure.hpp"

using namespace fdem;

namespace {

constexpr double kSigmaH = 20e6, kSigmah = 12e6;  // cases/tunnel-kirsch [Pa], compression

// cases/tunnel-kirsch on the committed coarse mesh; `extra` is appended.
std::string tunnel_case(const std::string& extra = "") {
  return "title = \"tunnel\"\n[mesh]\nfile = \"" + test::source_path("tests/data/cases/tunnel_small.msh") +
         "\"\n[time]\ndt = \"auto\"\nsafety = 0.5\nend = 50.0e-3\n[output]\ndir = \"out\"\nname = \"tunnel\"\n"
         "frames = 2\nhistory_every = 1.0e-3\n"
         "[[material]]\nname = \"rock\"\nregions = [\"rock\", \"tunnel\"]\ndensity = 2650.0\nyoung = 50.0e9\n"
         "poisson = 0.25\n[in_situ]\nstress = [-20.0e6, -12.0e6, 0.0]\n"
         "[[excavation]]\nregion = \"tunnel\"\nstart = 0.0\nduration = 8.0e-3\n[damping]\nlocal = 0.8\n"
         "[[boundary]]\nregion = \"bottom\"\nfix = [\"y\"]\n[[boundary]]\nregion = \"left\"\nfix = [\"x\"]\n"
         "[[boundary]]\nregion = \"right\"\nin_situ = true\n[[boundary]]\nregion = \"top\"\nin_situ = true\n" +
         extra;
}

std::string edited(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

std::string bytes(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

using Cli = test::FdemResult;
Cli fdem_cli(const std::string& args) { return test::run_fdem_cli(args); }

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("excavation: a tunnel in a stressed plate gives Kirsch's hoop stress at the wall, the account closed") {
  test::TempDir dir;
  const std::string path = dir.write("tunnel.toml", tunnel_case());
  const RunSummary run = test::run(path, {"output.dir=\"" + dir.str() + "/out\""});
  const std::string exo = dir.str() + "/out/tunnel.exo";
  for (double angle : {0.0, 90.0}) {
    const test::WallHoop h = test::wall_hoop(exo, 1.0, kSigmaH, kSigmah, angle, 0.3, 8.0);
    MESSAGE("θ = " << angle << "°: σ_θθ at the wall " << h.measured / 1e6 << " MPa, Kirsch " << h.kirsch / 1e6
                   << " MPa, error " << 100 * h.error() << "% (" << h.triangles << " triangles)");
    CHECK(std::fabs(h.error()) < 0.10);
  }
  // The hole: the tunnel's triangles are marked removed, the rock's not.
  const PreparedCase p = prepare_case(path, {"output.dir=\"" + dir.str() + "/out\""});
  const auto gone = test::last_element_values(exo, "EXCAVATED");
  REQUIRE(gone.size() == p.model.num_triangles());
  size_t removed = 0;
  for (size_t t = 0; t < gone.size(); ++t) {
    CHECK(gone[t] == (p.model.triangle_excavation[t] >= 0 ? 1.0 : 0.0));
    removed += gone[t] == 1.0;
  }
  CHECK(removed > 10);
  // The account: the tunnel's strain energy left with it (positive: the core was
  // compressed), and the balance stays closed.
  const auto excavated = test::read_variable(dir.str() + "/out/tunnel_history.nc", "excavated_energy");
  MESSAGE("excavated_energy at the end " << excavated.back() << " J, worst |energy_error| " << run.worst_energy_error);
  CHECK(excavated.back() != 0);
  CHECK(std::fabs(run.worst_energy_error) < 1e-3);
  // Quasi-static at the end: the largest out-of-balance force is a small part of the
  // mean internal force per node.
  const auto ratio = test::read_variable(dir.str() + "/out/tunnel_history.nc", "unbalanced_ratio");
  MESSAGE("unbalanced_ratio at the end " << ratio.back());
  CHECK(ratio.back() < 0.01);
}

TEST_CASE("excavation: without it the wall keeps the field's stress (the Kirsch check above can fail)") {
  test::TempDir dir;
  const std::string path = dir.write("tunnel.toml", edited(tunnel_case(), "start = 0.0", "start = 1.0"));
  test::run(path, {"output.dir=\"" + dir.str() + "/out\""});
  const test::WallHoop h = test::wall_hoop(dir.str() + "/out/tunnel.exo", 1.0, kSigmaH, kSigmah, 0.0, 0.3, 8.0);
  MESSAGE("not excavated: σ_θθ at θ = 0 " << h.measured / 1e6 << " MPa against Kirsch's " << h.kirsch / 1e6);
  CHECK(std::fabs(h.error()) > 0.10);
}

TEST_CASE("excavation: a run to T and a run to T/2 restarted across the removal write the same bytes") {
  // 2,400 µs in all, restarted at 1,200 µs: a ramp from 0 to 2 ms (the restart inside it,
  // the end after it), and a sudden removal at 1.5 ms (after the restart). Both close the
  // account.
  for (const std::string& timing : {std::string("start = 0.0\nduration = 2.0e-3"), std::string("start = 1.5e-3\nduration = 0.0")}) {
    CAPTURE(timing);
    test::TempDir dir;
    const std::string text = edited(edited(tunnel_case(), "end = 50.0e-3", "end = 2.4e-3"),
                                    "start = 0.0\nduration = 8.0e-3", timing);
    const std::string path = dir.write("tunnel.toml", text);
    const std::string one = dir.str() + "/one", two = dir.str() + "/two";
    const RunSummary whole = test::run(path, {"output.dir=\"" + one + "\""});
    test::run(path, {"output.dir=\"" + two + "\"", "time.end=1.2e-3"});
    const RunSummary rest = test::run(path, {"output.dir=\"" + two + "\""}, test::restart_from(two + "/tunnel.ckpt"));
    CHECK(rest.first_step > 0);
    for (const char* f : {"/tunnel.exo", "/tunnel_history.nc"}) {
      CAPTURE(f);
      CHECK(bytes(one + f) == bytes(two + f));
    }
    const auto gone = test::last_element_values(one + "/tunnel.exo", "EXCAVATED");
    CHECK(*std::max_element(gone.begin(), gone.end()) == 1.0);
    const auto excavated = test::read_variable(one + "/tunnel_history.nc", "excavated_energy");
    MESSAGE("excavated_energy " << excavated.back() << " J, worst |energy_error| " << whole.worst_energy_error);
    // The ramp releases the core's strain energy; the sudden removal of a core that never
    // deformed (W = 0 at F = I, the prestress stores nothing) releases none.
    if (timing.rfind("start = 0.0", 0) == 0) CHECK(excavated.back() > 0);
    else CHECK(std::fabs(excavated.back()) < 1e-3);
    CHECK(std::fabs(whole.worst_energy_error) < 1e-3);
  }
}

TEST_CASE("excavation: bad entries are refused with the file and the key; fdem check exits 2") {
  test::TempDir dir;
  auto error = [&](const std::string& text) -> std::string {
    try {
      prepare_case(dir.write("c.toml", text), {"output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string good = tunnel_case();
  CHECK(error(good).empty());
  const std::string name = error(edited(good, "region = \"tunnel\"\nstart", "region = \"tunel\"\nstart"));
  CHECK(name.find("c.toml:") != std::string::npos);
  CHECK(name.find("excavation[0].region = \"tunel\": no physical surface of that name") != std::string::npos);
  CHECK(name.find("did you mean 'tunnel'") != std::string::npos);
  const std::string curve = error(edited(good, "region = \"tunnel\"\nstart", "region = \"top\"\nstart"));
  CHECK(curve.find("excavation[0].region = \"top\": no physical surface of that name") != std::string::npos);
  const std::string duration = error(edited(good, "duration = 8.0e-3", "duration = -1.0"));
  CHECK(duration.find("c.toml:") != std::string::npos);
  CHECK(duration.find("excavation[0].duration") != std::string::npos);
  const std::string start = error(edited(good, "start = 0.0", "start = -1.0"));
  CHECK(start.find("excavation[0].start") != std::string::npos);
  CHECK(error(edited(good, "duration = 8.0e-3", "duration = 8.0e-3\ndepth = 3.0")).find("depth") != std::string::npos);
  CHECK(error(good + "[[excavation]]\nregion = \"tunnel\"\n").find("already excavated by") != std::string::npos);
  CHECK(error(edited(good, "region = \"tunnel\"\nstart", "region = \"rock\"\nstart")).empty());
  CHECK(error(good + "[contact]\nnormal_penalty = 1e10\n").empty());  // since issue 31, item 5
  const Cli check = fdem_cli("check " + dir.write("d.toml", edited(good, "duration = 8.0e-3", "duration = -1.0")));
  MESSAGE(check.output);
  CHECK(check.code == 2);
  CHECK(check.output.find("d.toml:") != std::string::npos);
  const Cli ok = fdem_cli("check " + dir.write("e.toml", good) + " --set output.dir='\"" + dir.str() + "/out\"'");
  CHECK(ok.code == 0);
  CHECK(ok.output.find("excavation 'tunnel': ") != std::string::npos);
}

}  // TEST_SUITE
