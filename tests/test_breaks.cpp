// The break catalogue and seismic events (OUT/NAME_events.nc): the records against the
// per-step broken flags, their energy against the CE4s' own dissipation, the grouping
// rule on breaks with a known answer, the file, restart and repeatability.
#include <doctest/doctest.h>
#include <netcdf.h>

#include <cmath>
#include <fstream>
#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "approx.hpp"
#include "case_files.hpp"
#include "case_reader_fixture.hpp"
#include "engine/outputs/fracture_events.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"
#include "fracture_tables.hpp"

using namespace fdem;

namespace {

// A 0.6 m × 0.1 m bar meshed in code (MSH 2.2, so no gmsh is needed): 12 × 2 squares of
// 0.05 m, two triangles each; surfaces "p1" (x < 0.2), "p2", "p3" (x > 0.4), curves
// "left", "right", "bottom".
std::string bar_mesh(const test::TempDir& dir) {
  const int nx = 12, ny = 2;
  const double h = 0.05;
  std::ostringstream m;
  m << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n6\n1 1 \"left\"\n1 2 \"right\"\n1 3 \"bottom\"\n"
    << "2 11 \"p1\"\n2 12 \"p2\"\n2 13 \"p3\"\n$EndPhysicalNames\n$Nodes\n" << (nx + 1) * (ny + 1) << "\n";
  auto node = [&](int i, int j) { return 1 + i + j * (nx + 1); };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m << node(i, j) << " " << i * h << " " << j * h << " 0\n";
  m << "$EndNodes\n$Elements\n" << 2 * ny + nx + 2 * nx * ny << "\n";
  int id = 0;
  for (int j = 0; j < ny; ++j) m << ++id << " 1 2 1 1 " << node(0, j) << " " << node(0, j + 1) << "\n";
  for (int j = 0; j < ny; ++j) m << ++id << " 1 2 2 2 " << node(nx, j) << " " << node(nx, j + 1) << "\n";
  for (int i = 0; i < nx; ++i) m << ++id << " 1 2 3 3 " << node(i, 0) << " " << node(i + 1, 0) << "\n";
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int phys = i < 4 ? 11 : i < 8 ? 12 : 13;
      const int a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
      m << ++id << " 2 2 " << phys << " " << phys << " " << a << " " << b << " " << c << "\n";
      m << ++id << " 2 2 " << phys << " " << phys << " " << a << " " << c << " " << d << "\n";
    }
  m << "$EndElements\n";
  return dir.write("bar2.msh", m.str());
}

const char* const kStrong = test::kStrongFracture;

// Three pieces of the same rock bonded by two weak interfaces (x = 0.2 and 0.4 m), the
// ends pulled apart at 0.5 m/s each: both weak sections break, the rock does not.
std::string two_sections(const test::TempDir& dir, const std::string& out, double end, const std::string& output = "") {
  std::ostringstream c;
  c << "title = \"two weak sections\"\n[mesh]\nfile = \"" << bar_mesh(dir) << "\"\n[time]\ndt = \"auto\"\nend = " << end
    << "\n[output]\ndir = \"" << out << "\"\nname = \"bar\"\nevery = 1e-4\nhistory_every = 1e-5\n" << output;
  for (const char* piece : {"p1", "p2", "p3"})
    c << "[[material]]\nname = \"" << piece << "\"\nregions = [\"" << piece
      << "\"]\ndensity = 2000.0\nyoung = 10e9\npoisson = 0.2\nviscosity = \"critical\"\n" << kStrong;
  for (const char* pair : {"[\"p1\", \"p2\"]", "[\"p2\", \"p3\"]"})
    c << "[[interface]]\nmaterials = " << pair
      << "\ntensile_strength = 1e6\ncohesion = 2e6\nfriction_angle = 30.0\ngf1 = 10.0\ngf2 = 100.0\n"
         "penalty = { opening = 100e9, sliding = 100e9, overlap = 100e9 }\n";
  c << "[[boundary]]\nregion = \"left\"\nvelocity = [-0.5, 0.0]\nrise = 5e-5\n"
       "[[boundary]]\nregion = \"right\"\nvelocity = [0.5, 0.0]\nrise = 3e-4\n"
       "[[boundary]]\nregion = \"bottom\"\nfix = [\"y\"]\n";
  return dir.write(out.substr(out.find_last_of('/') + 1) + ".toml", c.str());
}

bool same_bytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
  return !sa.empty() && sa == sb;
}

io::BreakRecord at(double t, double x, double y, double energy, long ce4) {
  io::BreakRecord b;
  b.time = t, b.x = x, b.y = y, b.energy = energy, b.ce4 = ce4, b.mode = 1;
  return b;
}

}  // namespace

TEST_SUITE("breaks") {

TEST_CASE("[output] events = { distance, window }: read, optional, positive, unknown keys named with the near one") {
  test::case_reader::CaseDir d;
  const auto c = io::read_case(d.write("c.toml", test::case_reader::kBase + "[output]\nevents = { distance = 0.01, window = 2e-6 }\n"));
  CHECK(c.output.events_distance == 0.01);
  CHECK(c.output.events_window == 2e-6);
  const auto none = io::read_case(d.write("d.toml", test::case_reader::kBase));
  CHECK(none.output.events_distance == 0.0);  // 0: the default from the model
  CHECK(none.output.events_window == 0.0);
  const auto half = io::read_case(d.write("e.toml", test::case_reader::kBase + "[output]\nevents = { window = 1e-5 }\n"));
  CHECK(half.output.events_distance == 0.0);
  CHECK(half.output.events_window == 1e-5);
  CHECK(test::case_reader::error_of(test::case_reader::kBase + "[output]\nevents = { distance = -1.0 }\n") != "");
  const std::string typo = test::case_reader::error_of(test::case_reader::kBase + "[output]\nevents = { distanse = 1.0 }\n").c_str();
  CHECK(typo.find("distanse") != std::string::npos);
  CHECK(typo.find("distance") != std::string::npos);
}

TEST_CASE("events: single linkage in space and time, transitive, with counts, centroids, energies, magnitudes") {
  // Chain A: 0-1-2 each 0.8 apart (distance 1) → one event although 0 and 2 are 1.6 apart.
  // B: near A in space but 5 s later (window 1) → its own event. C: at the same time as A
  // but 10 m away → its own. D: two breaks 0.5 s apart at one point, energy 0 → NaN.
  const std::vector<io::BreakRecord> breaks = {
      at(0.0, 0.0, 0.0, 1e6, 0),  at(0.0, 10.0, 0.0, 2e6, 5), at(0.2, 0.8, 0.0, 2e6, 1),
      at(0.9, 1.6, 0.0, 3e6, 2),  at(5.0, 0.4, 0.0, 4e6, 3),  at(6.0, 30.0, 30.0, 0.0, 7),
      at(6.5, 30.0, 30.0, 0.0, 8), at(8.0, 2.4, 0.0, 1e6, 4)};
  const auto ev = group_events(breaks, io::EventRule{1.0, 1.0});
  REQUIRE(ev.size() == 5);
  CHECK(ev[0].breaks == 3);  // A, in the order of first breaks
  CHECK(ev[0].start == 0.0);
  CHECK(ev[0].end == 0.9);
  CHECK(ev[0].x == doctest::Approx(0.8));
  CHECK(ev[0].energy == 6e6);
  CHECK(ev[0].magnitude == doctest::Approx(2.0 / 3.0 * (std::log10(6e6) - 4.8)));
  CHECK(ev[1].breaks == 1);  // C
  CHECK(ev[1].x == 10.0);
  CHECK(ev[2].breaks == 1);  // B
  CHECK(ev[2].start == 5.0);
  CHECK(ev[3].breaks == 2);  // D
  CHECK(ev[3].energy == 0.0);
  CHECK(std::isnan(ev[3].magnitude));
  CHECK(ev[4].breaks == 1);  // the last one: 2.4 is within 1 of nothing alive at t = 8
  CHECK(std::isnan(event_magnitude(0.0)));
  CHECK(std::isnan(event_magnitude(-1.0)));
  CHECK(test::abs_near(event_magnitude(std::pow(10.0, 4.8)), 0.0, 1e-12));
  // A window of 10 s joins B to A (0.4 from break 0), and then the break at t = 8 (0.8 from 1.6).
  const auto wide = group_events(breaks, io::EventRule{1.0, 10.0});
  REQUIRE(wide.size() == 3);
  CHECK(wide[0].breaks == 5);
  CHECK(wide[0].end == 8.0);
  CHECK(group_events({}, io::EventRule{1.0, 1.0}).empty());
  // Against the definition by brute force on a random set.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<io::BreakRecord> random;
  for (int k = 0; k < 300; ++k) random.push_back(at(u(rng), u(rng), u(rng), 1.0, k));
  std::sort(random.begin(), random.end(), [](const auto& a, const auto& b) { return a.time < b.time; });
  const io::EventRule rule{0.7, 0.3};
  std::vector<int> label(random.size());
  for (size_t i = 0; i < label.size(); ++i) label[i] = int(i);
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t i = 0; i < random.size(); ++i)
      for (size_t j = 0; j < random.size(); ++j)
        if (std::fabs(random[i].time - random[j].time) <= rule.window &&
            std::hypot(random[i].x - random[j].x, random[i].y - random[j].y) <= rule.distance && label[j] < label[i])
          label[i] = label[j], changed = true;
  }
  std::map<int, long> sizes;
  for (int l : label) ++sizes[l];
  const auto grouped = group_events(random, rule);
  REQUIRE(grouped.size() == sizes.size());
  size_t k = 0;
  for (const auto& [first, count] : sizes) CHECK(grouped[k++].breaks == count);
}

TEST_CASE("the catalogue holds exactly the CE4s that broke, at the step they broke, with their dissipation") {
  test::TempDir dir;
  const PreparedCase p = prepare_case(two_sections(dir, dir.str() + "/out", 4e-4), {});
  Solver solver(test::context(), p.model, p.dt);
  CohesiveForces& ce4 = *solver.cohesive();
  const size_t n = p.model.ce4.size();
  std::vector<int> was(n, 0);
  std::map<long, io::BreakRecord> expected;  // by CE4, from the per-step flags
  std::vector<io::BreakRecord> drained;
  for (long s = 1; s <= p.steps; ++s) {
    const auto x = solver.positions();
    const double t = solver.time();
    solver.step(false);
    const auto now = ce4.broken();
    for (size_t e = 0; e < n; ++e)
      if (now[e] && !was[e]) {
        io::BreakRecord b;
        const auto& c = p.model.ce4[e];
        const real2 a = x[c[0]], bb = x[c[1]], cc = x[c[2]], d = x[c[3]];
        b.x = 0.25 * ((a.x + bb.x) + (cc.x + d.x));
        b.y = 0.25 * ((a.y + bb.y) + (cc.y + d.y));
        b.time = t;
        expected[long(e)] = b;
      }
    was = now;
    if (s % 13 == 0 || s == p.steps) {
      const auto fresh = ce4.drain_breaks();
      for (size_t k = 1; k < fresh.size(); ++k)
        CHECK((fresh[k - 1].time < fresh[k].time || (fresh[k - 1].time == fresh[k].time && fresh[k - 1].ce4 < fresh[k].ce4)));
      drained.insert(drained.end(), fresh.begin(), fresh.end());
    }
  }
  const auto mode = ce4.mode();
  const auto dissipated = ce4.dissipated();
  const auto broken_time = ce4.broken_time();
  MESSAGE(expected.size() << " of " << n << " CE4s broke in " << p.steps << " steps");
  CHECK(expected.size() >= 4);  // both weak sections (two CE4s each) at least
  REQUIRE(drained.size() == expected.size());
  CHECK(drained.size() == ce4.count_broken());
  CHECK(ce4.catalogue().size() == drained.size());
  double sum_records = 0, sum_broken = 0;
  for (const auto& b : drained) {
    REQUIRE(expected.count(b.ce4) == 1);
    const auto& e = expected[b.ce4];
    CHECK(b.time == test::rel(e.time, 1e-12));
    CHECK(b.time == double(broken_time[b.ce4]));
    CHECK(b.x == test::rel(e.x, 1e-13));
    CHECK(b.y == test::rel(e.y, 1e-13));
    CHECK(b.mode == mode[b.ce4]);
    CHECK(b.mode >= 1);
    CHECK(b.energy == double(dissipated[b.ce4]));
    CHECK(b.energy > 0);
    CHECK(b.length == test::rel(0.05, kDoublePrecision ? 1e-12 : 1e-7));  // the weak sections are vertical edges (h is a `real`)
    const double x_mid = b.x;
    CHECK((std::fabs(x_mid - 0.2) < 0.01 || std::fabs(x_mid - 0.4) < 0.01));
    sum_records += b.energy;
    sum_broken += double(dissipated[b.ce4]);
  }
  // The catalogue's energy is the broken CE4s' share of fracture_dissipation.
  CHECK(std::fabs(sum_records - sum_broken) <= 1e-9 * sum_broken);
  // ... and fracture_dissipation is that share plus what unbroken CE4s dissipated.
  double unbroken = 0;
  for (size_t e = 0; e < n; ++e)
    if (!was[e]) unbroken += double(dissipated[e]);
  CHECK(ce4.fracture_dissipation() == doctest::Approx(sum_broken + unbroken).epsilon(1e-12));
}

TEST_CASE("events file: the catalogue as the run wrote it, events, unlimited break dimension, repeatable bytes") {
  test::TempDir dir;
  const std::string a = dir.str() + "/a", b = dir.str() + "/b";
  const std::string events = "events = { distance = 0.1, window = 1e-3 }\n";
  const auto run_a = test::run(two_sections(dir, a, 4e-4, events));
  test::run(two_sections(dir, b, 4e-4, events));
  const std::string file = a + "/bar_events.nc";
  CHECK(same_bytes(file, b + "/bar_events.nc"));
  const auto broken = test::read_variable(a + "/bar_history.nc", "broken_ce4");
  const auto times = test::read_variable(file, "break_time");
  CHECK(double(times.size()) == broken.back());
  CHECK(run_a.breaks == times.size());
  for (size_t k = 1; k < times.size(); ++k) CHECK(times[k - 1] <= times[k]);
  const auto x = test::read_variable(file, "break_x");
  const auto energy = test::read_variable(file, "break_energy");
  const auto tri_a = test::read_variable(file, "break_tri_a"), tri_b = test::read_variable(file, "break_tri_b");
  const auto ce4 = test::read_variable(file, "break_ce4");
  const PreparedCase p = prepare_case(a + ".toml", {});
  for (size_t k = 0; k < ce4.size(); ++k) {
    CHECK(tri_a[k] == p.model.ce4_triangles[size_t(ce4[k])][0]);
    CHECK(tri_b[k] == p.model.ce4_triangles[size_t(ce4[k])][1]);
  }
  for (const char* v : {"break_y", "break_length", "break_mode"}) CHECK(test::read_variable(file, v).size() == times.size());
  // Two sections 0.2 m apart, grouped within 0.1 m: two events, one per section.
  const auto ev_breaks = test::read_variable(file, "event_breaks");
  const auto ev_x = test::read_variable(file, "event_x");
  const auto ev_energy = test::read_variable(file, "event_energy");
  const auto ev_m = test::read_variable(file, "event_magnitude");
  REQUIRE(ev_breaks.size() == 2);
  CHECK(ev_breaks[0] + ev_breaks[1] == double(times.size()));
  CHECK(std::fabs(std::fabs(ev_x[0] - ev_x[1]) - 0.2) < 0.01);
  double total = 0;
  for (double e : energy) total += e;
  CHECK(ev_energy[0] + ev_energy[1] == doctest::Approx(total).epsilon(1e-12));
  for (size_t k = 0; k < 2; ++k) CHECK(ev_m[k] == doctest::Approx(2.0 / 3.0 * (std::log10(ev_energy[k]) - 4.8)));
  CHECK(test::read_variable(file, "event_start").size() == 2);
  CHECK(test::read_variable(file, "event_end").size() == 2);
  CHECK(test::read_variable(file, "event_y").size() == 2);
  // The break dimension is the unlimited one; units and long names are there.
  int nc = -1, dim = -1, unlimited = -1, var = -1;
  REQUIRE(nc_open(file.c_str(), NC_NOWRITE, &nc) == NC_NOERR);
  CHECK(nc_inq_dimid(nc, "break", &dim) == NC_NOERR);
  CHECK(nc_inq_unlimdim(nc, &unlimited) == NC_NOERR);
  CHECK(unlimited == dim);
  for (const char* v : {"break_time", "break_energy", "break_ce4", "event_magnitude"}) {
    REQUIRE(nc_inq_varid(nc, v, &var) == NC_NOERR);
    size_t len = 0;
    CHECK(nc_inq_attlen(nc, var, "units", &len) == NC_NOERR);
    CHECK(nc_inq_attlen(nc, var, "long_name", &len) == NC_NOERR);
  }
  double distance = 0;
  CHECK(nc_get_att_double(nc, NC_GLOBAL, "event_distance", &distance) == NC_NOERR);
  CHECK(distance == 0.1);
  nc_close(nc);
  // The defaults: 3 × the mean CE4 length, and that over the fastest P wave.
  const auto rule = event_rule(p.model, 0, 0);
  double mean = 0;
  for (real h : [&] {
         std::vector<real> hs;
         Solver s(test::context(), p.model, p.dt);
         for (size_t e = 0; e < p.model.ce4.size(); ++e) hs.push_back(s.cohesive()->parameters()[layout::COH_STRIDE * e + layout::COH_H]);
         return hs;
       }())
    mean += double(h);
  mean /= double(p.model.ce4.size());
  CHECK(rule.distance == test::rel(3 * mean, kDoublePrecision ? 1e-12 : 1e-6));  // the rule sums the mesh's edges, the test the `real` h
  CHECK(rule.window == test::rel(rule.distance / std::sqrt(p.model.materials[0].wave_modulus / 2000.0), 1e-12));
}

TEST_CASE("restart: the events file of T/2 + restart to T is the bytes of one run to T; later records dropped") {
  test::TempDir dir;
  const std::string one = dir.str() + "/one", two = dir.str() + "/two";
  test::run(two_sections(dir, one, 4e-4));
  // The section at x = 0.2 m breaks at about 160 µs, the one at 0.4 m (its end's load
  // rises slower) at about 260 µs.
  const auto half = test::run(two_sections(dir, two, 2e-4));
  const auto ckpt_breaks = half.breaks;
  // A file that ran further than the checkpoint (as after a crash): its later records
  // must not survive the restart.
  std::filesystem::copy_file(one + "/bar_events.nc", two + "/bar_events.nc",
                             std::filesystem::copy_options::overwrite_existing);
  const auto rest = test::run(two_sections(dir, two, 4e-4), {}, test::restart_from(two + "/bar.ckpt"));
  MESSAGE(ckpt_breaks << " breaks before the checkpoint, " << rest.breaks << " in all");
  CHECK(ckpt_breaks > 0);
  CHECK(rest.breaks > ckpt_breaks);
  CHECK(same_bytes(one + "/bar_events.nc", two + "/bar_events.nc"));
  CHECK(same_bytes(one + "/bar_history.nc", two + "/bar_history.nc"));
}

}  // TEST_SUITE
