// Joints ([[joint]], issue 31 item 3): the CE4s on a joint's curves take the joint's
// properties; a broken joint starts closed; the break catalogue says which breaks are on
// a joint; bad entries are refused with the file, line and key. The specimens are
// cases/jaeger's (a 50 × 100 mm rectangle with one joint through its centre at β), at the
// case's coarse size; the Jaeger check at two angles is the fast version of the
// validation series (validation/runs.cpp, entry `jaeger`).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <sys/wait.h>

#include "approx.hpp"
#include "base/errors.hpp"
#include "case_files.hpp"
#include "fdem_cli.hpp"
#include "engine/model/model.hpp"
#include "engine/run/prepare_case.hpp"
#include "fixture.hpp"
#include "io/joint_geometry.hpp"
#include "jaeger_measure.hpp"

using namespace fdem;

namespace {

const double kPi = std::acos(-1.0);

std::string jaeger_case() { return test::source_path("cases/jaeger/case.toml"); }

// The case at angle β (cases/jaeger/bNN.geo), output in `dir`, with more --sets.
std::vector<std::string> at_angle(int beta, const test::TempDir& dir, std::vector<std::string> more = {}) {
  more.push_back("mesh.geo=\"" + test::source_path("cases/jaeger/b" + std::to_string(beta) + ".geo") + "\"");
  more.push_back("output.dir=\"" + dir.str() + "/out\"");
  return more;
}

std::string edited(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

std::string file_text(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  REQUIRE(f != nullptr);
  std::string text;
  char buffer[4096];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  std::fclose(f);
  return text;
}

using Cli = test::FdemResult;
Cli fdem_cli(const std::string& args) { return test::run_fdem_cli(args); }

}  // namespace

TEST_SUITE("joints") {

TEST_CASE("joints: the CE4s of a joint follow its line and cover it, and take the joint's properties") {
  for (int beta : {35, 70}) {  // side to side, and bottom to top
    CAPTURE(beta);
    test::TempDir dir;
    const PreparedCase p = prepare_case(jaeger_case(), at_angle(beta, dir));
    const Model& m = p.model;
    REQUIRE(m.ce4_joint.size() == m.ce4.size());
    REQUIRE(m.joint_names.size() == 1);
    CHECK(m.joint_names[0] == "joint");
    // The line through the centre at β from x, clipped to the 50 × 100 mm rectangle.
    const double b = beta * kPi / 180, dx = std::cos(b), dy = std::sin(b);
    const double half = std::min(0.025 / dx, 0.05 / dy);  // half the line's length [m]
    double length = 0, worst = 0;
    size_t on = 0;
    for (size_t e = 0; e < m.ce4.size(); ++e) {
      const auto& c = m.ce4[e];
      const double ax = m.x[c[0]], ay = m.y[c[0]], bx = m.x[c[1]], by = m.y[c[1]];
      const double mx = 0.5 * (ax + bx), my = 0.5 * (ay + by);
      const double distance = std::fabs(-dy * mx + dx * my);  // from the line
      const FractureProperties& f = m.fracture[m.ce4_properties[e]];
      if (m.ce4_joint[e] == 0) {
        ++on;
        worst = std::max(worst, distance);
        length += std::hypot(bx - ax, by - ay);
        CHECK(f.cohesion == 2.0e6);
        CHECK(f.tensile_strength == 0.5e6);
        CHECK(f.friction_angle == 30.0);
        CHECK(f.gf1 == 1.0);
        CHECK(f.gf2 == 5.0);
      } else {
        CHECK(m.ce4_joint[e] == -1);
        CHECK(f.cohesion == 9.0e6);
        // No rock CE4 lies along the line: every edge on it is the joint's.
        const double da = std::fabs(-dy * ax + dx * ay), db = std::fabs(-dy * bx + dx * by);
        CHECK(!(da < 1e-9 && db < 1e-9));
      }
    }
    MESSAGE("beta " << beta << ": " << on << " joint CE4s, " << length << " m of " << 2 * half << " m, worst "
                    << worst << " m off the line");
    CHECK(on >= 10);
    CHECK(worst < 1e-9);
    CHECK(length == test::rel(2 * half, 1e-9));
  }
}

TEST_CASE("joints: a broken joint starts closed, no break of it is recorded, and JOINT marks it in the frames") {
  test::TempDir dir;
  const std::string text = edited(edited(file_text(jaeger_case()), "tensile_strength = 0.5e6\ncohesion = 2.0e6          # c_j\n", "broken = true\n"),
                                  "gf1 = 1.0                 # small: the joint gives within a few µm of slip past its peak,\n"
                                  "                          # so its break marks the peak (README, How it is measured)\n"
                                  "gf2 = 5.0\n", "");
  const std::string path = dir.write("broken.toml", edited(text, "geo = \"b45.geo\"", "geo = \"" + test::source_path("cases/jaeger/b60.geo") + "\""));
  const auto summary = test::run(path, {"output.dir=\"" + dir.str() + "/out\"", "time.end=2e-5", "output.frames=1"});
  CHECK(summary.steps > 0);
  const std::string exo = dir.str() + "/out/jaeger.exo";
  const auto broken = test::last_element_values(exo, "BROKEN", 2);
  const auto joint = test::last_element_values(exo, "JOINT", 2);
  const auto rock_joint = test::last_element_values(exo, "JOINT", 1);
  REQUIRE(broken.size() == joint.size());
  size_t on = 0;
  for (size_t e = 0; e < joint.size(); ++e) {
    CHECK(broken[e] == (joint[e] == 1 ? 1 : 0));
    on += joint[e] == 1;
  }
  CHECK(on >= 10);
  for (double v : rock_joint) CHECK(v == 0);
  CHECK(test::read_variable(dir.str() + "/out/jaeger_events.nc", "break_time").empty());
}

TEST_CASE("joints: Jaeger at beta = 45 and 60 (sigma_3 = 0): the joint slips at the formula's sigma_1 within 10%") {
  for (int beta : {45, 60}) {
    CAPTURE(beta);
    test::TempDir dir;
    const double expected = test::jaeger_strength(beta, 0.0, 2.0e6, 30.0);
    // σ1 rises at 10 MPa/ms: run to 1.3 × the expected peak.
    const double end = 1.3 * expected / 1e10;
    // At size 8 mm (about 220 TRI3, twice the case's Δt): a few seconds a run.
    const PreparedCase p = prepare_case(jaeger_case(), at_angle(beta, dir, {"time.end=" + std::to_string(end), "mesh.size=8.0"}));
    size_t joint_ce4s = 0;
    for (int j : p.model.ce4_joint) joint_ce4s += j == 0;
    test::run(p);
    const test::JaegerPeak peak = test::jaeger_peak(dir.str() + "/out/jaeger_events.nc", p.config, joint_ce4s / 2);
    MESSAGE("beta " << beta << ": peak sigma_1 " << peak.sigma1 / 1e6 << " MPa against " << expected / 1e6
                    << " MPa (Jaeger); " << peak.joint_breaks << " of " << peak.breaks << " breaks on the joint");
    CHECK(peak.on_joint);
    CHECK(peak.sigma1 == doctest::Approx(expected).epsilon(0.10));
  }
}

// cases/jaeger/case.toml on the intact specimen with its [[joint]]'s `curves` line
// replaced by `source` (a file or a set).
std::string intact_with(const std::string& source) {
  std::string text = edited(file_text(jaeger_case()), "geo = \"b45.geo\"",
                            "geo = \"" + test::source_path("cases/jaeger/intact.geo") + "\"");
  return edited(text, "curves = [\"joint\"]\n", source);
}

// Distance from p to the polyline.
double polyline_distance(const std::vector<io::Point2>& line, double x, double y) {
  double best = 1e300;
  for (size_t k = 0; k + 1 < line.size(); ++k) {
    const auto a = line[k], b = line[k + 1];
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double t = std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    best = std::min(best, std::hypot(x - a[0] - t * dx, y - a[1] - t * dy));
  }
  return best;
}

TEST_CASE("joints: a polyline file is embedded: the joint's CE4s follow the polyline and cover it") {
  test::TempDir dir;
  const std::vector<io::Point2> line = {{-0.015, -0.03}, {0.0, 0.0}, {0.015, -0.02}};  // inside 50 × 100 mm
  dir.write("v.txt", "# a V-shaped joint [m]\n-0.015 -0.03\n0.0 0.0   # its vertex\n0.015 -0.02\n");
  const std::string path = dir.write("c.toml", intact_with("file = \"v.txt\"\n"));
  const PreparedCase p = prepare_case(path, {"output.dir=\"" + dir.str() + "/out\""});
  const Model& m = p.model;
  double length = 0, worst = 0;
  size_t on = 0;
  for (size_t e = 0; e < m.ce4.size(); ++e) {
    if (m.ce4_joint[e] != 0) continue;
    const auto& c = m.ce4[e];
    ++on;
    worst = std::max(worst, polyline_distance(line, 0.5 * (m.x[c[0]] + m.x[c[1]]), 0.5 * (m.y[c[0]] + m.y[c[1]])));
    worst = std::max(worst, polyline_distance(line, m.x[c[0]], m.y[c[0]]));
    length += std::hypot(m.x[c[1]] - m.x[c[0]], m.y[c[1]] - m.y[c[0]]);
    CHECK(m.fracture[m.ce4_properties[e]].cohesion == 2.0e6);
  }
  const double expected = std::hypot(0.015, 0.03) + std::hypot(0.015, 0.02);
  MESSAGE(on << " joint CE4s, " << length << " m of " << expected << " m, worst " << worst << " m off the polyline");
  CHECK(on >= 10);
  CHECK(worst < 1e-9);
  CHECK(length == test::rel(expected, 1e-9));

  // Outside the specimen, a bad line, a polyline of one point: refused with the file and line.
  auto error = [&](const std::string& text) -> std::string {
    dir.write("bad.txt", text);
    try {
      prepare_case(dir.write("d.toml", intact_with("file = \"bad.txt\"\n")), {"output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string outside = error("0.0 0.0\n0.01 0.01\n\n1.0 1.0\n1.1 1.0\n");
  CHECK(outside.find("bad.txt:5: the joint segment") != std::string::npos);
  CHECK(outside.find("lies outside the meshed region") != std::string::npos);
  CHECK(error("0.0 0.0\n0.01 0.01 0.02\n").find("bad.txt:2: expected a point") != std::string::npos);
  CHECK(error("0.0 0.0\n\n0.01 0.01\n").find("bad.txt:1: a polyline of one point") != std::string::npos);
  const Cli check = fdem_cli("check " + dir.write("e.toml", intact_with("file = \"bad.txt\"\n")) + " --set output.dir='\"" +
                            dir.str() + "/out\"'");
  CHECK(check.code == 2);
  CHECK(check.output.find("bad.txt:") != std::string::npos);
}

TEST_CASE("joints: a joint set is the same for the same seed, and its mean direction and spacing are the keys'") {
  io::JointSetConfig set;
  set.angle = 30, set.kappa = 20, set.spacing = 1.0, set.trace_length = 2.0, set.persistence = 0.5, set.seed = 7;
  const io::JointSetDraw a = io::draw_joint_set(set, {0, 0}, {400, 400}, 0);
  const io::JointSetDraw b = io::draw_joint_set(set, {0, 0}, {400, 400}, 0);
  REQUIRE(a.traces.size() == b.traces.size());
  CHECK(a.offsets == b.offsets);
  CHECK(a.angles == b.angles);
  bool same = true;
  for (size_t k = 0; k < a.traces.size(); ++k) same = same && a.traces[k].a == b.traces[k].a && a.traces[k].b == b.traces[k].b;
  CHECK(same);
  set.seed = 8;
  CHECK(io::draw_joint_set(set, {0, 0}, {400, 400}, 0).offsets != a.offsets);
  // Mean spacing of the lines, mean direction (circular) and spread of the traces.
  const double spacing = (a.offsets.back() - a.offsets.front()) / double(a.offsets.size() - 1);
  double sx = 0, sy = 0;
  for (double angle : a.angles) sx += std::cos(angle * kPi / 180), sy += std::sin(angle * kPi / 180);
  const double mean = std::atan2(sy, sx) * 180 / kPi, resultant = std::hypot(sx, sy) / double(a.angles.size());
  // von Mises: the mean resultant length is I1(κ)/I0(κ), 0.9747 at κ = 20.
  MESSAGE(a.offsets.size() << " lines, mean spacing " << spacing << " m; " << a.angles.size() << " traces, mean direction "
                           << mean << "°, mean resultant length " << resultant);
  CHECK(spacing == doctest::Approx(1.0).epsilon(0.10));
  CHECK(std::fabs(mean - 30) < 0.5);
  CHECK(resultant == doctest::Approx(0.9747).epsilon(0.01));
  // Persistence: the traces cover half of each line (traces of 2 m, bridges of 2 m).
  CHECK(a.traces.size() == doctest::Approx(a.offsets.size() * 2 * (std::hypot(400, 400) / 2 + 2) / 4).epsilon(0.05));
}

TEST_CASE("joints: a joint set embedded in the specimen: the same seed gives the same model bitwise; bad keys refused") {
  test::TempDir dir;
  const std::string set = "set = { angle = 60.0, kappa = 50.0, spacing = 0.02, trace_length = 0.03, persistence = 0.6, seed = 11 }\n";
  const std::string path = dir.write("c.toml", intact_with(set));
  const PreparedCase p1 = prepare_case(path, {"output.dir=\"" + dir.str() + "/out1\""});
  const PreparedCase p2 = prepare_case(path, {"output.dir=\"" + dir.str() + "/out2\""});
  size_t on = 0;
  for (int j : p1.model.ce4_joint) on += j == 0;
  MESSAGE(on << " joint CE4s of " << p1.model.ce4.size());
  CHECK(on >= 10);
  CHECK(p1.model.x == p2.model.x);
  CHECK(p1.model.y == p2.model.y);
  CHECK(p1.model.ce4 == p2.model.ce4);
  CHECK(p1.model.ce4_joint == p2.model.ce4_joint);
  const PreparedCase p3 = prepare_case(path, {"output.dir=\"" + dir.str() + "/out3\"", "joint.0.set.seed=12"});
  CHECK(p3.model.ce4_joint != p1.model.ce4_joint);
  auto error = [&](const std::string& text) -> std::string {
    try {
      prepare_case(dir.write("d.toml", intact_with(text)), {"output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string negative = error(edited(set, "spacing = 0.02", "spacing = -0.02"));
  CHECK(negative.find("d.toml:") != std::string::npos);
  CHECK(negative.find("joint[0].set.spacing") != std::string::npos);
  const std::string unknown = error(edited(set, "seed = 11", "seed = 11, dip = 3.0"));
  CHECK(unknown.find("unknown key 'dip'") != std::string::npos);
  CHECK(error(edited(set, ", seed = 11", "")).find("seed") != std::string::npos);
  CHECK(error(edited(set, "persistence = 0.6", "persistence = 1.5")).find("joint[0].set.persistence") != std::string::npos);
  const std::string none = error("curves = [\"top\"]\n" + set);
  CHECK(none.find("lies on the boundary") != std::string::npos);
  const Cli check = fdem_cli("check " + path + " --set output.dir='\"" + dir.str() + "/out4\"'");
  CHECK(check.code == 0);
  CHECK(check.output.find("joint     joint[0] 'joint' on a set (angle 60°") != std::string::npos);
}

TEST_CASE("joints: bad [[joint]] entries are refused with the file, the line and the key; fdem check exits 2") {
  test::TempDir dir;
  const std::string good = edited(file_text(jaeger_case()), "geo = \"b45.geo\"",
                                  "geo = \"" + test::source_path("cases/jaeger/b45.geo") + "\"");
  auto error = [&](const std::string& text) -> std::string {
    try {
      prepare_case(dir.write("c.toml", text), {"output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  CHECK(error(good).empty());
  const std::string unknown = error(edited(good, "cohesion = 2.0e6 ", "cohesoin = 2.0e6 "));
  CHECK(unknown.find("c.toml:") != std::string::npos);
  CHECK(unknown.find("unknown key 'cohesoin'") != std::string::npos);
  const std::string curve = error(edited(good, "curves = [\"joint\"]", "curves = [\"joitn\"]"));
  CHECK(curve.find("c.toml:") != std::string::npos);
  CHECK(curve.find("joint[0] ('joint').curves: no physical curve 'joitn'") != std::string::npos);
  CHECK(curve.find("did you mean 'joint'") != std::string::npos);
  const std::string boundary = error(edited(good, "curves = [\"joint\"]", "curves = [\"top\"]"));
  CHECK(boundary.find("joint[0] ('joint').curves") != std::string::npos);
  CHECK(boundary.find("lies on the boundary of the body") != std::string::npos);
  const std::string surface = error(edited(good, "curves = [\"joint\"]", "curves = [\"rock\"]"));
  CHECK(surface.find("is a physical surface") != std::string::npos);
  const std::string negative = error(edited(good, "cohesion = 2.0e6 ", "cohesion = -2.0e6 "));
  CHECK(negative.find("c.toml:") != std::string::npos);
  CHECK(negative.find("joint[0].cohesion") != std::string::npos);
  const std::string broken = error(edited(good, "curves = [\"joint\"]", "curves = [\"joint\"]\nbroken = true"));
  CHECK(broken.find("joint[0].tensile_strength is not allowed with broken = true") != std::string::npos);
  const std::string missing = error(edited(good, "curves = [\"joint\"]\n", ""));
  CHECK(missing.find("curves") != std::string::npos);
  // The rock without [material.fracture]: a joint needs fracturable triangles.
  const std::string elastic = error(edited(good, "[material.fracture]\ntensile_strength = 3.0e6\ncohesion = 9.0e6\n"
                                                 "friction_angle = 30.0\ngf1 = 20.0\ngf2 = 200.0\n"
                                                 "penalty = { opening = 2.0e11, sliding = 2.0e11, overlap = 2.0e11 }   # 10 E: quasi-static, the least without a warning\n",
                                           ""));
  CHECK(elastic.find("borders material 'rock', which has no [material.fracture]") != std::string::npos);
  const std::string twice = error(good + "[[joint]]\nname = \"other\"\ncurves = [\"joint\"]\nbroken = true\nfriction_angle = 20.0\n"
                                         "penalty = { opening = 1.0e12, sliding = 1.0e12, overlap = 1.0e12 }\n");
  CHECK(twice.find("curve 'joint' is already in joint[0]") != std::string::npos);

  const Cli bad = fdem_cli("check " + dir.write("d.toml", edited(good, "cohesion = 2.0e6 ", "cohesoin = 2.0e6 ")));
  MESSAGE(bad.output);
  CHECK(bad.code == 2);
  CHECK(bad.output.find("d.toml:") != std::string::npos);
  const Cli ok = fdem_cli("check " + dir.write("e.toml", good) + " --set output.dir='\"" + dir.str() + "/out\"'");
  MESSAGE(ok.output);
  CHECK(ok.code == 0);
  CHECK(ok.output.find("joint     joint[0] 'joint' on 'joint': ") != std::string::npos);
  CHECK(ok.output.find("c 2e+06 Pa, friction angle 30°") != std::string::npos);
}

}  // TEST_SUITE
