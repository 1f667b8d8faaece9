// [fluid]: the flow network on the cracks (engine/stages/fluid_flow.*, cl_kernels/fluid_flow.cl).
// Sneddon's pressurised crack on a coarse mesh, the mass balance of a rate source, the
// energy account, determinism and the refusal of bad keys.
#include <algorithm>
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/wait.h>

#include "approx.hpp"
#include "base/errors.hpp"
#include "case_files.hpp"
#include "fdem_cli.hpp"
#include "engine/model/fluid_spring.hpp"
#include "engine/run/prepare_case.hpp"
#include "engine/solver.hpp"
#include "engine/stages/fluid_flow.hpp"
#include "fixture.hpp"
#include "io/case_config.hpp"

using namespace fdem;

namespace {

constexpr double kYoung = 10e9, kPoisson = 0.25, kPressure = 1e6, kHalfLength = 1.0;

// cases/sneddon with `overrides` (the committed case; the coarse tests mesh it at a larger size).
PreparedCase sneddon(const std::vector<std::string>& overrides) {
  return prepare_case(test::source_path("cases/sneddon/case.toml"), overrides);
}

// The crack's openings as the faces' nodes give them: at the centre (x = 0) and the
// crack's volume per unit thickness (trapezoid over its CE4s) [m, m²].
struct CrackOpening {
  double centre = 0, volume = 0;
};
CrackOpening crack_opening(const Model& m, const std::vector<real2>& x) {
  CrackOpening c;
  for (uint32_t e : m.fluid.crack_ce4) {
    const auto& n = m.ce4[e];  // (i, j, j', i')
    const double cx = (x[n[1]].x - x[n[0]].x) + (x[n[2]].x - x[n[3]].x);
    const double cy = (x[n[1]].y - x[n[0]].y) + (x[n[2]].y - x[n[3]].y);
    const double l = std::hypot(cx, cy), nx = cy / l, ny = -cx / l;
    const double oa = (x[n[3]].x - x[n[0]].x) * nx + (x[n[3]].y - x[n[0]].y) * ny;
    const double ob = (x[n[2]].x - x[n[1]].x) * nx + (x[n[2]].y - x[n[1]].y) * ny;
    c.volume += m.fluid.segment_length[e] * 0.5 * (oa + ob);
    if (std::fabs(m.x[n[0]]) < 1e-9) c.centre = oa;
    if (std::fabs(m.x[n[1]]) < 1e-9) c.centre = ob;
  }
  return c;
}

// Sneddon (plane strain): w(0) = 4 (1 - ν²) p a / E, V = 2π (1 - ν²) p a² / E.
double sneddon_centre() { return 4 * (1 - kPoisson * kPoisson) * kPressure * kHalfLength / kYoung; }
double sneddon_volume() { return 2 * M_PI * (1 - kPoisson * kPoisson) * kPressure * kHalfLength * kHalfLength / kYoung; }

struct Outcome {
  CrackOpening opening;
  EnergyTotals energy;
  double energy_error = 0;
  std::vector<real2> positions;
};
// Runs `steps` steps of a prepared case on the test device, the last one an energy row.
Outcome run_steps(const PreparedCase& p, long steps, Solver** keep = nullptr) {
  static std::unique_ptr<Solver> solver;
  solver = std::make_unique<Solver>(test::context(), p.model, p.dt);
  for (long k = 0; k < steps; ++k) solver->step(k + 1 == steps);
  Outcome o;
  o.energy = solver->energy();
  o.energy_error = solver->balance().error(o.energy);
  o.positions = solver->positions();
  o.opening = crack_opening(p.model, o.positions);
  if (keep) *keep = solver.get();
  return o;
}

// The fluid stage in plain C++ (cl_kernels/fluid_flow.cl's step, every vertex visited):
// apertures and volumes of the carrying CE4s, the vertices' volumes and pressures, the
// sub-steps' fluxes, Carter's leak-off and the source, and the faces' forces.
struct FluidReference {
  const Model& m;
  const FluidModel& f;
  std::vector<std::array<double, 4>> state, energy;  // per vertex, as vertex_state / vertex_energy
  std::vector<double> rate;                           // per vertex: V's change over the last step
  std::vector<double> exposed;                        // per CE4
  std::vector<std::array<double, 2>> slots;           // 4 per CE4
  explicit FluidReference(const Model& model)
      : m(model), f(model.fluid), state(f.vertices, {0, 0, 0, 0}), energy(f.vertices, {0, 0, 0, 0}),
        rate(f.vertices, 0.0), exposed(model.ce4.size(), -1.0), slots(4 * model.ce4.size(), {0, 0}) {}
  static double excess(double v0, double v) { return v > 0 ? std::max(v0 / v - 1, 0.0) : 0.0; }
  // The pressure the faces' forces take: at the room predicted for mid-step, V + ½ ΔV_last
  // with the change bounded to ±V/4; the state's p where no change is predicted (a vertex
  // held at the source's pressure).
  double mid_step_pressure(size_t v) const {
    if (rate[v] == 0) return state[v][2];
    const double room = state[v][1] + std::clamp(0.5 * rate[v], -0.25 * state[v][1], 0.25 * state[v][1]);
    return f.bulk_modulus * excess(state[v][0], room);
  }
  double stored(double v, double d) const { return f.bulk_modulus * v * ((1 + d) * std::log1p(d) - d); }

  void step(double time, double dt, long substeps, const std::vector<real2>& x, const std::vector<int>& carries) {
    const size_t n_ce4 = m.ce4.size();
    const double th = m.thickness, K = f.bulk_modulus;
    std::vector<std::array<double, 4>> geom(n_ce4, {0, 0, 0, 0});
    std::vector<std::array<double, 2>> normal(n_ce4, {0, 0});
    for (size_t e = 0; e < n_ce4; ++e) {
      if (!carries[e]) continue;
      const auto& nd = m.ce4[e];
      const double xi = x[nd[0]].x, yi = x[nd[0]].y, xj = x[nd[1]].x, yj = x[nd[1]].y;
      const double xj2 = x[nd[2]].x, yj2 = x[nd[2]].y, xi2 = x[nd[3]].x, yi2 = x[nd[3]].y;
      const double cx = (xj - xi) + (xj2 - xi2), cy = (yj - yi) + (yj2 - yi2), l = std::hypot(cx, cy);
      const double nx = cy / l, ny = -cx / l;
      const double wa = std::max((xi2 - xi) * nx + (yi2 - yi) * ny, 0.0) + f.residual_aperture;
      const double wb = std::max((xj2 - xj) * nx + (yj2 - yj) * ny, 0.0) + f.residual_aperture;
      const double h = f.segment_length[e], wm = 0.5 * (wa + wb);
      geom[e] = {h * th * (3 * wa + wb) / 8, h * th * (wa + 3 * wb) / 8, wm * wm * wm * th / (12 * f.viscosity * h), wm};
      normal[e] = {nx, ny};
    }
    std::vector<char> source(f.vertices, 0), held(f.vertices, 0);
    for (uint32_t v : f.source_vertices) source[v] = 1, held[v] = f.pressure_source;
    for (size_t v = 0; v < f.vertices; ++v) {
      double volume = 0;
      for (uint32_t k = f.vertex_start[v]; k < f.vertex_start[v + 1]; ++k) {
        const uint32_t end = f.vertex_end[k];
        volume += (end & 1u) ? geom[end >> 1][1] : geom[end >> 1][0];
      }
      auto& s = state[v];
      const double d = excess(s[0], volume);
      if (volume != s[1]) energy[v][1] += mid_step_pressure(v) * (volume - s[1]);
      rate[v] = held[v] ? 0.0 : volume - s[1];
      s = {s[0], volume, K * d, stored(volume, d)};
    }
    const double dt_sub = dt / double(substeps), share = 1.0 / double(f.source_vertices.size());
    for (long k = 0; k < substeps; ++k) {
      const double t_sub = time + dt_sub * double(k);
      const double value = fluid_source_value(f.history, time + dt_sub * (double(k) + (f.pressure_source ? 1.0 : 0.5)));
      const double source_value = f.pressure_source ? value : value * th * share;
      const auto start = state;  // every flux from the sub-step's start
      for (size_t e = 0; e < n_ce4; ++e)  // exposure: open, fluid at one end
        if (geom[e][2] != 0 && exposed[e] < 0 &&
            (start[f.segment_vertex[2 * e]][0] > 0 || start[f.segment_vertex[2 * e + 1]][0] > 0))
          exposed[e] = t_sub;
      for (size_t v = 0; v < f.vertices; ++v) {
        double inflow = 0, leak = 0;
        for (uint32_t j = f.vertex_start[v]; j < f.vertex_start[v + 1]; ++j) {
          const uint32_t end = f.vertex_end[j], e = end >> 1;
          if (geom[e][2] != 0) {
            const double q = geom[e][2] * (start[f.segment_vertex[2 * e]][2] - start[f.segment_vertex[2 * e + 1]][2]);
            inflow += (end & 1u) ? q : -q;
          }
          if (exposed[e] >= 0) leak += f.segment_length[e] * (std::sqrt(t_sub + dt_sub - exposed[e]) - std::sqrt(t_sub - exposed[e]));
        }
        leak *= 2 * f.leak_off * th;
        auto& s = state[v];
        if (inflow == 0 && !source[v] && leak == 0) continue;
        s[0] += dt_sub * inflow;
        const double u_flowed = stored(s[1], excess(s[0], s[1]));
        auto& en = energy[v];
        en[3] += s[3] - u_flowed;
        leak = std::min(leak, std::max(s[0], 0.0));
        if (leak > 0) s[0] -= leak;
        if (source[v] && s[1] > 0) {
          const double added = f.pressure_source ? s[1] * (1 + source_value / K) - s[0] : dt_sub * source_value;
          const double h_work = f.pressure_source ? K * std::log1p(source_value / K)
                                                  : K * std::log1p(excess(s[0] + 0.5 * added, s[1]));
          s[0] += added;
          en[0] += h_work * added;
          en[2] += added;
        }
        const double d = excess(s[0], s[1]);
        s[2] = K * d;
        s[3] = stored(s[1], d);
      }
    }
    for (size_t e = 0; e < n_ce4; ++e) {
      for (int c = 0; c < 4; ++c) slots[4 * e + c] = {0, 0};
      if (geom[e][2] == 0) continue;
      const double pa = mid_step_pressure(f.segment_vertex[2 * e]), pb = mid_step_pressure(f.segment_vertex[2 * e + 1]);
      const double ht = f.segment_length[e] * th / 8;
      const double fa = ht * (3 * pa + pb), fb = ht * (pa + 3 * pb);
      const double nx = normal[e][0], ny = normal[e][1];
      slots[4 * e] = {-fa * nx, -fa * ny};
      slots[4 * e + 1] = {-fb * nx, -fb * ny};
      slots[4 * e + 2] = {fb * nx, fb * ny};
      slots[4 * e + 3] = {fa * nx, fa * ny};
    }
  }
};

// `fdem ARGS` with its output and exit code.
std::pair<int, std::string> run_fdem(const std::string& args) {
  test::FdemResult r = test::run_fdem_cli(args);
  return {r.code, std::move(r.output)};
}

// The coarse Sneddon case: 10 edges along the crack (mesh.size = 0.2).
const std::vector<std::string> kCoarse{"mesh.size=0.2", "output.dir=\"/tmp/fdem_test_fluid_out\""};

}  // namespace

TEST_SUITE("fluid") {

// On 10 edges the mesh is too coarse for 3% (PoCL: centre -4.4%, volume -9.8%): the
// tolerances are 10% and 15%, which a force of the wrong size or sign fails by far.
// (test::rel, tests/approx.hpp: doctest's Approx adds 1 to its scale, and on figures of
// 1e-4 m or m³ an epsilon of 0.1 would pass anything.)
TEST_CASE("fluid: Sneddon's crack on a coarse mesh (10 edges) opens as the formula says, within 10-15%") {
  const PreparedCase p = sneddon(kCoarse);
  REQUIRE(p.model.fluid.enabled);
  CHECK(p.model.fluid.crack_ce4.size() == 10);
  const long steps = static_cast<long>(std::lround(0.006 / p.dt));  // the ramp (2 ms) and the settling after it
  const Outcome o = run_steps(p, steps);
  MESSAGE("centre opening " << o.opening.centre << " m (Sneddon " << sneddon_centre() << "), volume " << o.opening.volume
                            << " m² (Sneddon " << sneddon_volume() << "), energy_error " << o.energy_error);
  CHECK(o.opening.centre == test::rel(sneddon_centre(), 0.10));
  CHECK(o.opening.volume == test::rel(sneddon_volume(), 0.15));
  CHECK(std::fabs(o.energy_error) < 0.01);
  // The work of the pressure on the faces went into the solid, less what the damping took.
  CHECK(o.energy.fluid_face_work > 0);
  CHECK(o.energy.fluid_injection == doctest::Approx(o.energy.fluid_face_work + o.energy.fluid_stored).epsilon(0.01));
  CHECK(o.energy.wellbore_pressure == doctest::Approx(kPressure));
}

// The committed case as it is (40 edges along the crack, 23.5k steps: minutes on PoCL):
// cases/sneddon/README.md's figures. Skipped by default; run it with
//   build/fdem_tests -tc="fluid: Sneddon's case*" --no-skip
TEST_CASE("fluid: Sneddon's case (40 edges): opening at the centre and volume within 3%" * doctest::skip()) {
  const PreparedCase p = sneddon({"output.dir=\"/tmp/fdem_test_fluid_out\""});
  REQUIRE(p.model.fluid.crack_ce4.size() == 40);
  const Outcome o = run_steps(p, p.steps);
  MESSAGE("steps " << p.steps << ", dt " << p.dt << " s: centre opening " << o.opening.centre << " m (Sneddon "
                   << sneddon_centre() << ", " << 100 * (o.opening.centre / sneddon_centre() - 1) << "%), volume "
                   << o.opening.volume << " m² (Sneddon " << sneddon_volume() << ", "
                   << 100 * (o.opening.volume / sneddon_volume() - 1) << "%), energy_error " << o.energy_error
                   << ", injected " << o.energy.fluid_injected_volume << " m³, in the network " << o.energy.fluid_volume
                   << " m³, crack volume " << o.energy.crack_volume << " m³");
  CHECK(o.opening.centre == test::rel(sneddon_centre(), 0.03));
  CHECK(o.opening.volume == test::rel(sneddon_volume(), 0.03));
  CHECK(std::fabs(o.energy_error) < 0.01);
}

TEST_CASE("fluid: mass balance of a rate source at the well: injected = stored within 0.1%; dry cracks stay dry") {
  // The well (the crack's centre) injects Q = 0.02 m²/s; the crack starts dry (V₀ = 0).
  const std::string dir = test::source_path("cases/sneddon/case.toml");
  test::TempDir tmp;
  std::string text;
  {
    std::ifstream in(dir);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  const size_t at = text.find("pressure = { times");
  REQUIRE(at != std::string::npos);
  text = text.substr(0, at) + "rate = 2e-4\n";
  const size_t geo = text.find("geo = \"sneddon.geo\"");
  REQUIRE(geo != std::string::npos);
  text.replace(geo, std::string("geo = \"sneddon.geo\"").size(), "geo = \"" + test::source_path("cases/sneddon/sneddon.geo") + "\"");
  text.replace(text.find("source = \"crack\""), std::string("source = \"crack\"").size(), "source = \"well\"");
  const std::string path = tmp.write("rate.toml", text);
  // A soft fluid in a thin crack (its stiffness K_f/V (∂V/∂x)² is not in the stable step
  // yet) and a thin one, so that it spreads along several segments in 400 steps.
  std::vector<std::string> sets = kCoarse;
  for (const char* s : {"fluid.bulk_modulus=1e6", "fluid.residual_aperture=1e-6", "fluid.viscosity=2e-8",
                        "fluid.max_aperture=1e-4", "fluid.rate=2e-2"})
    sets.push_back(s);
  const PreparedCase p = prepare_case(path, sets);
  REQUIRE(p.model.fluid.source_vertices.size() == 1);
  CHECK(!p.model.fluid.pressure_source);
  Solver* solver = nullptr;
  // The explicit coupling's error is largest while the crack is at its residual aperture
  // (the fluid's spring is stiffest): energy_error 2.6% after 100 steps, 1.2% after 400,
  // 0.8% after 1000 (PoCL).
  const long steps = 1000;
  const Outcome o = run_steps(p, steps, &solver);
  const double expected = 2e-2 * p.model.thickness * p.dt * static_cast<double>(steps);
  MESSAGE("injected " << o.energy.fluid_injected_volume << " m³ (Q t " << expected << "), in the network "
                      << o.energy.fluid_volume << " m³, crack volume " << o.energy.crack_volume << ", well pressure "
                      << o.energy.wellbore_pressure << " Pa, energy_error " << o.energy_error);
  CHECK(o.energy.fluid_injected_volume == test::rel(expected, 1e-6));
  CHECK(o.energy.fluid_volume == test::rel(o.energy.fluid_injected_volume, 0.001));
  CHECK(o.energy.wellbore_pressure > 0);
  CHECK(o.energy.fluid_viscous > 0);
  CHECK(std::fabs(o.energy_error) < 0.01);
  // Fluid only where an open segment reaches: every vertex off the crack holds none.
  const auto state = solver->fluid()->vertex_state();
  std::vector<char> on_crack(p.model.fluid.vertices, 0);
  for (uint32_t e : p.model.fluid.crack_ce4)
    on_crack[p.model.fluid.segment_vertex[2 * e]] = on_crack[p.model.fluid.segment_vertex[2 * e + 1]] = 1;
  size_t wet_off_crack = 0, wet = 0;
  for (size_t v = 0; v < state.size(); ++v) {
    wet += state[v].x > 0;
    wet_off_crack += state[v].x != 0 && !on_crack[v];
  }
  CHECK(wet > 1);  // it spread from the well
  CHECK(wet_off_crack == 0);
}

// Carter's leak-off (fluid.leak_off = C_L): the coarse Sneddon crack held at its pressure
// (every crack vertex a source) leaks 2 C_L / √(t - t_e) per unit area from every segment,
// all exposed from the first sub-step: leaked(t) = 4 C_L L t_z √(t - t_e) (L = 2 m, the
// crack's length; t_z the thickness), so ∝ √t; what the source gives = what the network
// holds + what leaked.
TEST_CASE("fluid: Carter leak-off from a held-pressure crack: leaked volume = 4 C_L L √t, injected = network + leaked") {
  constexpr double kLeakOff = 1e-3;  // m/√s
  std::vector<std::string> sets = kCoarse;
  sets.push_back("fluid.leak_off=1e-3");
  const PreparedCase p = sneddon(sets);
  REQUIRE(p.model.fluid.leak_off == kLeakOff);
  Solver solver(test::context(), p.model, p.dt);
  const long quarter = static_cast<long>(std::lround(0.0015 / p.dt)), steps = 4 * quarter;
  std::vector<EnergyTotals> rows;
  for (long k = 0; k < steps; ++k) {
    solver.step((k + 1) % quarter == 0);
    if ((k + 1) % quarter == 0) rows.push_back(solver.energy());
  }
  const EnergyTotals& end = rows.back();
  const double t = p.dt * static_cast<double>(steps), t_e = p.dt / static_cast<double>(solver.fluid()->substeps());
  const double expected = 4 * kLeakOff * 2 * kHalfLength * p.model.thickness * std::sqrt(t - t_e);
  const double error = solver.balance().error(end);
  MESSAGE("leaked " << end.fluid_leaked_volume << " m³ (4 C_L L √t " << expected << "), at t/4 "
                    << rows.front().fluid_leaked_volume << " (formula " << expected / 2 << ")" << ", injected " << end.fluid_injected_volume
                    << " m³, in the network " << end.fluid_volume << " m³, leak-off energy " << end.fluid_leak_off
                    << " J, energy_error " << error);
  // Early on a vertex cannot leak more than it holds (a closed crack holds w_r per metre
  // while Carter's rate is infinite at t_e): the total falls a little short of the formula;
  // from t/4 on the leak is the formula's to 0.1%: 4 C_L L t_z (√t - √(t/4)).
  // (Relative checks, test::rel: doctest's Approx adds 1 to its scale, so on volumes of
  // 1e-4 m³ an epsilon of 1e-3 would pass anything.)
  CHECK(end.fluid_leaked_volume <= expected * (1 + 1e-9));
  CHECK(end.fluid_leaked_volume >= 0.85 * expected);  // the ramp from p = 0: a closed crack holds w_r
  const double late = 4 * kLeakOff * 2 * kHalfLength * p.model.thickness * (std::sqrt(t - t_e) - std::sqrt(t / 4 - t_e));
  CHECK(end.fluid_leaked_volume - rows.front().fluid_leaked_volume == test::rel(late, 1e-3));
  CHECK(end.fluid_leaked_volume > end.fluid_volume);  // a leak that matters
  CHECK(end.fluid_injected_volume == test::rel(end.fluid_volume + end.fluid_leaked_volume, 1e-3));
  CHECK(end.fluid_leak_off > 0);
  CHECK(std::fabs(error) < 0.01);
}

// cases/kgd on a coarse mesh (mesh.size = 0.2: 5 edges of 0.2 m seed the crack on each
// side of the well), the viscosity-dominated case at 30 times its rate for 2.5 ms: the
// crack grows from the seed along the weak line only (the interface; each half's own
// CE4s are strong), symmetric about the well, and the volumes balance. The full-size
// comparison with the vertex solutions is tests/kgd_validate.sh (ctest label validate).
TEST_CASE("fluid: KGD coarse: the crack grows along the weak line only, both wings alike; injected = network within 0.1%") {
  const PreparedCase p = prepare_case(test::source_path("cases/kgd/viscosity.toml"),
                                      {"mesh.size=0.2", "fluid.rate=10", "output.dir=\"/tmp/fdem_test_fluid_kgd\""});
  REQUIRE(p.model.fluid.crack_ce4.size() == 10);
  Solver solver(test::context(), p.model, p.dt);
  const long steps = static_cast<long>(std::lround(2.5e-3 / p.dt));
  for (long k = 0; k < steps; ++k) solver.step(k + 1 == steps);
  const EnergyTotals e = solver.energy();
  std::vector<int> broken, mode;
  solver.cohesive()->flags(broken, mode);
  double left = 0, right = 0;
  size_t off_line = 0, on_line = 0;
  for (size_t c = 0; c < p.model.ce4.size(); ++c) {
    if (!broken[c]) continue;
    const auto& n = p.model.ce4[c];
    const double mx = 0.5 * (p.model.x[n[0]] + p.model.x[n[1]]), my = 0.5 * (p.model.y[n[0]] + p.model.y[n[1]]);
    if (std::fabs(my) > 1e-9) {
      ++off_line;
      continue;
    }
    ++on_line;
    right = std::max(right, mx + 0.1), left = std::max(left, -mx + 0.1);
  }
  MESSAGE("steps " << steps << ": broken on the line " << on_line << ", off it " << off_line << ", wings " << left << " m and "
                   << right << " m, injected " << e.fluid_injected_volume << " m³, in the network " << e.fluid_volume
                   << " m³, well pressure " << e.wellbore_pressure << " Pa");
  CHECK(off_line == 0);
  CHECK(on_line >= 14);  // the seed's 10 and at least 2 more edges on each side
  CHECK(left == doctest::Approx(right).epsilon(0.25));
  // Relative (test::rel): doctest's Approx adds 1 to its scale (no use on 1e-2 m³).
  CHECK(e.fluid_volume == test::rel(e.fluid_injected_volume, 1e-3));
  const double injected = 10 * p.model.thickness * p.dt * static_cast<double>(steps);
  CHECK(e.fluid_injected_volume == test::rel(injected, 1e-6));
}

// fluid.segments: with "damaged" (the default) a CE4 carries fluid from the step one of its
// Gauss points softens, so the fluid fills the cohesive zone ahead of the broken crack; with
// "broken" only broken CE4s do. The coarse KGD case of the test above at 2 ms: every
// segment that carries fluid is broken or softened (D_max > 0), the "damaged" run has
// softened intact segments with fluid in them and the "broken" run none.
TEST_CASE("fluid: segments = \"damaged\" lets the fluid into softened intact CE4s, \"broken\" only into broken ones") {
  for (const std::string rule : {"damaged", "broken"}) {
    CAPTURE(rule);
    const PreparedCase p = prepare_case(
        test::source_path("cases/kgd/viscosity.toml"),
        {"mesh.size=0.2", "fluid.rate=10", "fluid.segments=\"" + rule + "\"", "output.dir=\"/tmp/fdem_test_fluid_seg\""});
    Solver solver(test::context(), p.model, p.dt);
    const long steps = static_cast<long>(std::lround(2.0e-3 / p.dt));
    for (long k = 0; k < steps; ++k) solver.step(k + 1 == steps);
    std::vector<int> broken, mode;
    solver.cohesive()->flags(broken, mode);
    const size_t n = p.model.ce4.size();
    const auto gauss = download<real>(test::context(), solver.cohesive()->gauss_state(), 9 * n);
    std::vector<real> pressure, aperture;
    solver.fluid()->segment_fields(pressure, aperture);
    size_t carrying = 0, softened_carrying = 0, broken_count = 0, wet_softened = 0;
    for (size_t e = 0; e < n; ++e) {
      const bool softened = gauss[9 * e] > 0 || gauss[9 * e + 3] > 0 || gauss[9 * e + 6] > 0;
      broken_count += broken[e] != 0;
      if (aperture[e] <= 0) {
        CHECK_MESSAGE(!broken[e], "a broken CE4 carries no fluid: " << e);
        if (rule == "damaged") CHECK_MESSAGE(!softened, "a softened CE4 carries no fluid: " << e);
        continue;
      }
      ++carrying;
      CHECK_MESSAGE((broken[e] || (softened && rule == "damaged")), "CE4 " << e << " carries fluid");
      if (!broken[e]) {
        ++softened_carrying;
        wet_softened += pressure[e] > 0;
      }
    }
    MESSAGE(rule << ": " << carrying << " segments carry fluid, " << broken_count << " CE4s broken, " << softened_carrying
                 << " softened intact ones carry fluid (" << wet_softened << " of them under pressure)");
    if (rule == "damaged") {
      CHECK(softened_carrying > 0);
      CHECK(wet_softened > 0);
    } else {
      CHECK(softened_carrying == 0);
    }
  }
}

TEST_CASE("fluid: a run to T and a run to T/2 restarted to T give the same history (the fluid's state is in the checkpoint)") {
  // The well injects into a dry crack (the mass-balance test's case): the fluid moves
  // before and after the checkpoint.
  test::TempDir tmp;
  std::string text;
  {
    std::ifstream in(test::source_path("cases/sneddon/case.toml"));
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  text = text.substr(0, text.find("pressure = { times")) + "rate = 2e-2\n";
  text.replace(text.find("geo = \"sneddon.geo\""), std::string("geo = \"sneddon.geo\"").size(),
               "geo = \"" + test::source_path("cases/sneddon/sneddon.geo") + "\"");
  text.replace(text.find("source = \"crack\""), std::string("source = \"crack\"").size(), "source = \"well\"");
  const std::string path = tmp.write("rate.toml", text);
  auto sets = [&](const std::string& out, const char* end) {
    std::vector<std::string> s{"mesh.size=0.2", "output.dir=\"" + tmp.str() + "/" + out + "\"", "output.history_every=2e-5",
                               std::string("time.end=") + end, "fluid.bulk_modulus=1e6", "fluid.residual_aperture=1e-6",
                               "fluid.viscosity=2e-8", "fluid.max_aperture=1e-4"};
    return s;
  };
  test::run(path, sets("one", "2e-4"));
  test::run(path, sets("two", "1e-4"));
  test::run(path, sets("two", "2e-4"), test::restart_from(tmp.str() + "/two/sneddon.ckpt"));
  for (const char* name : {"injected_volume", "fluid_volume", "crack_volume", "wellbore_pressure", "fluid_stored_energy",
                           "fluid_viscous_dissipation", "energy_error"}) {
    CAPTURE(name);
    const auto a = test::read_variable(tmp.str() + "/one/sneddon_history.nc", name);
    const auto b = test::read_variable(tmp.str() + "/two/sneddon_history.nc", name);
    REQUIRE(a.size() == b.size());
    size_t differ = 0;
    for (size_t k = 0; k < a.size(); ++k) differ += a[k] != b[k];
    CHECK(differ == 0);
    if (std::string(name) == "fluid_volume") CHECK(a.back() > 1.5 * a[a.size() / 2 - 1]);  // it moved after T/2
  }
}

TEST_CASE("fluid: a segment wider than fluid.max_aperture stops the run, naming the CE4, the step and the key") {
  // The coarse Sneddon crack opens to 0.36 mm; the fluid's step planned for 0.01 mm.
  std::string message;
  try {
    test::run(test::source_path("cases/sneddon/case.toml"),
              {"mesh.size=0.2", "output.dir=\"/tmp/fdem_test_fluid_wide\"", "fluid.max_aperture=1e-5", "time.end=2e-3"});
  } catch (const NumericalError& e) {
    message = e.what();
  }
  CAPTURE(message);
  CHECK(message.find("opened wider than fluid.max_aperture") != std::string::npos);
  CHECK(message.find("CE4 ") != std::string::npos);
  CHECK(message.find("by step ") != std::string::npos);
}

TEST_CASE("fluid: the stage's kernels against the plain C++ reference (broken, softened and dry CE4s, leak-off)") {
  // Coarse models: KGD (a rate source at the well, 50 times the case's rate so the seed
  // fills within the steps) and Sneddon (a pressure held on the crack) with leak-off. The
  // faces moved at random (openings and overlaps of up to 0.3 mm), the crack broken (the
  // stage's constructor), a dry broken CE4 away from it and softened CE4s next to it;
  // steps with the positions moved between them.
  struct Variant {
    const char* path;
    std::vector<std::string> overrides;
    long steps;
    bool past_crack;  // the fluid must reach past the crack's vertices (into softened CE4s)
  };
  const std::vector<Variant> variants{
      {"cases/kgd/viscosity.toml", {"mesh.size=0.2", "fluid.rate=17.0"}, 40, false},
      {"cases/sneddon/case.toml", {"mesh.size=0.2", "fluid.leak_off=1e-9"}, 6, true}};
  // The reference takes the plan's sub-steps: so do the kernels here (the count the
  // network's rate allows is checked by the gas tests and the KGD runs).
  setenv("FDEM_FLUID_ADAPTIVE", "0", 1);
  struct Unset {
    ~Unset() { unsetenv("FDEM_FLUID_ADAPTIVE"); }
  } unset;
  for (const auto& variant : variants) {
    CAPTURE(variant.path);
    std::vector<std::string> overrides = variant.overrides;
    overrides.push_back("output.dir=\"/tmp/fdem_test_fluid_ref\"");
    const PreparedCase p = prepare_case(test::source_path(variant.path), overrides);
    const Model& m = p.model;
    REQUIRE(m.fluid.enabled);
    auto& cl = test::context();
    const size_t n_ce4 = m.ce4.size();
    std::vector<int> carries(n_ce4, 0);
    for (uint32_t e : m.fluid.crack_ce4) carries[e] = 1;
    std::vector<cl_int2> status(n_ce4, cl_int2{{0, 0}});
    std::vector<real> gauss(9 * n_ce4);  // three reals per Gauss point (CohesiveForces::gauss_state)
    // Softened: the CE4s that share a vertex with the seed but are not on it; broken and
    // dry: the CE4 farthest from the well.
    std::vector<char> seed_vertex(m.fluid.vertices, 0);
    for (uint32_t e : m.fluid.crack_ce4) seed_vertex[m.fluid.segment_vertex[2 * e]] = seed_vertex[m.fluid.segment_vertex[2 * e + 1]] = 1;
    size_t softened = 0, far = 0;
    double far_r = 0;
    for (size_t e = 0; e < n_ce4; ++e) {
      const auto& nd = m.ce4[e];
      const double r = std::hypot(m.x[nd[0]], m.y[nd[0]]);
      if (r > far_r) far_r = r, far = e;
      if (carries[e]) continue;
      if (seed_vertex[m.fluid.segment_vertex[2 * e]] || seed_vertex[m.fluid.segment_vertex[2 * e + 1]]) {
        gauss[9 * e + 3] = real(0.3);  // D_max of the second point
        carries[e] = 1;
        ++softened;
      }
    }
    status[far] = cl_int2{{1, 1}};
    carries[far] = 1;
    REQUIRE(softened > 0);
    compute::buffer position(cl.context(), m.num_nodes() * sizeof(real2));
    compute::buffer status_buffer(cl.context(), n_ce4 * sizeof(cl_int2));
    compute::buffer gauss_buffer(cl.context(), 9 * n_ce4 * sizeof(real));
    upload(cl, status_buffer, status);
    upload(cl, gauss_buffer, gauss);
    FluidFlow stage(cl, m, position, status_buffer, gauss_buffer, p.dt);
    const long substeps = FluidFlow::substeps(m.fluid, p.dt);
    FluidReference ref(m);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<real2> x(m.num_nodes());
    double time = 0;
    for (long step = 0; step < variant.steps; ++step) {
      for (size_t n = 0; n < m.num_nodes(); ++n) x[n] = {real(m.x[n] + 3e-4 * u(rng)), real(m.y[n] + 3e-4 * u(rng))};
      upload(cl, position, x);
      stage.enqueue(time, step);
      ref.step(time, p.dt, substeps, x, carries);
      time += p.dt;
    }
    const auto state = stage.vertex_state();
    const auto slots = download<real2>(cl, stage.slots(), 4 * n_ce4);
    double scale[4] = {0, 0, 0, 0}, worst[4] = {0, 0, 0, 0};
    size_t wet = 0;
    for (const auto& s : ref.state)
      for (int c = 0; c < 4; ++c) scale[c] = std::max(scale[c], std::fabs(s[c]));
    for (size_t v = 0; v < m.fluid.vertices; ++v) {
      const double got[4] = {state[v].x, state[v].y, state[v].z, state[v].w};
      for (int c = 0; c < 4; ++c) worst[c] = std::max(worst[c], std::fabs(got[c] - ref.state[v][c]) / scale[c]);
      wet += ref.state[v][0] > 0;
    }
    double force_scale = 0, force_worst = 0;
    for (const auto& f : ref.slots) force_scale = std::max({force_scale, std::fabs(f[0]), std::fabs(f[1])});
    for (size_t k = 0; k < slots.size(); ++k)
      force_worst = std::max({force_worst, std::fabs(slots[k].x - ref.slots[k][0]) / force_scale,
                              std::fabs(slots[k].y - ref.slots[k][1]) / force_scale});
    // The fluid moved from the well (KGD) or past the crack's vertices into the softened
    // CE4s (Sneddon, every crack vertex held); the dry broken CE4 holds none.
    size_t crack_vertices = 0;
    for (char c : seed_vertex) crack_vertices += c;
    CHECK(wet > (variant.past_crack ? crack_vertices : size_t(2)));
    CHECK(ref.state[m.fluid.segment_vertex[2 * far]][0] == 0);
    CHECK(state[m.fluid.segment_vertex[2 * far]].x == 0);
    for (int c = 0; c < 4; ++c) CHECK(scale[c] > 0);
    // V₀ and V to round-off; p = K_f (V₀/V - 1), U and the forces lose log10(K_f / p)
    // digits to the difference (K_f / p ~ 1e6 at Sneddon's first steps).
    const double tolerance[4] = {kDoublePrecision ? 1e-12 : 1e-5, kDoublePrecision ? 1e-12 : 1e-5,
                                 kDoublePrecision ? 1e-9 : 1e-2, kDoublePrecision ? 1e-9 : 1e-2};
    CAPTURE(worst[0]);
    CAPTURE(worst[1]);
    CAPTURE(worst[2]);
    CAPTURE(worst[3]);
    CAPTURE(force_worst);
    for (int c = 0; c < 4; ++c) CHECK(worst[c] <= tolerance[c]);
    CHECK(force_scale > 0);
    CHECK(force_worst <= tolerance[2]);
    // The gather reads a node's fluid slots only where the stage flagged the node: every
    // node of a carrying CE4 and no other, and no slot that holds a force is at an
    // unflagged node (a dry node's slots are the +0s they were made with).
    const auto flags = download<cl_uchar>(cl, stage.loaded_nodes(), m.num_nodes());
    std::vector<cl_uchar> expected(m.num_nodes(), 0);
    for (size_t e = 0; e < n_ce4; ++e)
      if (carries[e])
        for (int k = 0; k < 4; ++k) expected[m.ce4[e][k]] = 1;
    size_t flagged = 0, wrong_flags = 0, forces_unflagged = 0;
    for (size_t n = 0; n < m.num_nodes(); ++n) flagged += flags[n], wrong_flags += flags[n] != expected[n];
    for (size_t e = 0; e < n_ce4; ++e)
      for (int k = 0; k < 4; ++k)
        if ((slots[4 * e + k].x != 0 || slots[4 * e + k].y != 0) && flags[m.ce4[e][k]] == 0) ++forces_unflagged;
    CAPTURE(flagged);
    CHECK(flagged > 0);
    CHECK(wrong_flags == 0);
    CHECK(forces_unflagged == 0);
  }
}

TEST_CASE("fluid: the sub-steps in one work-group's launch, global or local, and the whole step in one (fused), give "
          "the launches' bits (KGD rate, held pressure)") {
  // FDEM_FLUID_GROUP=0 keeps one launch a sub-step; =1 takes the group whatever the size.
  // FDEM_FLUID_LOCAL=0 keeps the group on its global path; by default a small wet network
  // (at most 256 wet vertices of at most 12 CE4 ends) takes the local one.
  // FDEM_FLUID_FUSED=1 takes the whole step in one work-group (a GPU's default for small
  // models), =0 the stage's four launches. FDEM_FLUID_HEAD=1 runs that work-group as the
  // first of the triangle stage's launch, =0 (the default) on its own launch; it always
  // takes the global path (FluidFlow::head_defines), so the seventh way asks for the local
  // one and must still give the launches' bits.
  struct Run {
    std::string path;
    std::vector<std::string> sets;
    long steps;
  };
  const std::vector<Run> runs{
      {test::source_path("cases/kgd/viscosity.toml"), {"mesh.size=0.2", "fluid.rate=10", "output.dir=\"/tmp/fdem_tg\""}, 1500},
      {test::source_path("cases/sneddon/case.toml"), {"mesh.size=0.2", "fluid.pressure=1e6", "output.dir=\"/tmp/fdem_tg\""}, 150}};
  // (The gas always takes the group's global path: it follows the hole's gas from
  // sub-step to sub-step.)
  struct Unset {
    ~Unset() {
      unsetenv("FDEM_FLUID_GROUP");
      unsetenv("FDEM_FLUID_LOCAL");
      unsetenv("FDEM_FLUID_FUSED");
      unsetenv("FDEM_FLUID_HEAD");
    }
  } unset;
  for (const auto& r : runs) {
    CAPTURE(r.path);
    const PreparedCase p = prepare_case(r.path, r.sets);
    // The local path's limits hold, so the third and fifth runs take it.
    uint32_t degree = 0;
    for (size_t v = 0; v < p.model.fluid.vertices; ++v)
      degree = std::max(degree, p.model.fluid.vertex_start[v + 1] - p.model.fluid.vertex_start[v]);
    CHECK(degree <= 12);
    constexpr int kWays = 7;
    std::vector<real2> x[kWays];
    std::vector<real4> state[kWays];
    const char* group[kWays] = {"0", "1", "1", "1", "1", "1", "1"};
    const char* local[kWays] = {"1", "0", "1", "0", "1", "0", "1"};
    const char* fused[kWays] = {"0", "0", "0", "1", "1", "1", "1"};
    const char* head[kWays] = {"0", "0", "0", "0", "0", "1", "1"};
    for (int way = 0; way < kWays; ++way) {
      setenv("FDEM_FLUID_GROUP", group[way], 1);
      setenv("FDEM_FLUID_LOCAL", local[way], 1);
      setenv("FDEM_FLUID_FUSED", fused[way], 1);
      setenv("FDEM_FLUID_HEAD", head[way], 1);
      Solver solver(test::context(), p.model, p.dt);
      CHECK(solver.fluid()->one_group() == (way > 0));
      CHECK(solver.fluid()->fused() == (way > 2));
      CHECK(solver.fluid()->headed() == (way > 4));
      // The stress pass between steps (an output frame) launches no step of the liquid.
      for (long k = 0; k < r.steps; ++k) {
        solver.step(false);
        if (k % 500 == 250) solver.enqueue_stress();
      }
      x[way] = solver.positions();
      state[way] = solver.fluid()->vertex_state();
    }
    size_t wet = 0;
    for (size_t v = 0; v < state[0].size(); ++v) wet += state[0][v].x > 0;
    CHECK(wet > 4);  // the fluid moved
    CHECK(wet <= 256);
    for (int way = 1; way < kWays; ++way) {
      CAPTURE(way);
      REQUIRE(x[0].size() == x[way].size());
      size_t differ = 0;
      for (size_t i = 0; i < x[0].size(); ++i) differ += x[0][i].x != x[way][i].x || x[0][i].y != x[way][i].y;
      for (size_t v = 0; v < state[0].size(); ++v)
        differ += state[0][v].x != state[way][v].x || state[0][v].z != state[way][v].z ||
                  state[0][v].w != state[way][v].w;
      CHECK(differ == 0);
    }
  }
}

TEST_CASE("fluid: the cohesive stage's list of carrying CE4s holds each carrying CE4 once, as it grows") {
  // The fused step (fluid_step_group) walks the CE4s that cohesive_forces appended in the
  // step they started to carry (broken, or softened: D_max > 0 at a point), after
  // fluid_network_scan listed those that carried at the start. At each check the list is
  // the set the fluid's own rule gives from the CE4s' state, without repeats.
  const PreparedCase p = prepare_case(test::source_path("cases/kgd/viscosity.toml"),
                                      {"mesh.size=0.2", "fluid.rate=10", "output.dir=\"/tmp/fdem_tl\""});
  REQUIRE(p.model.fluid.damaged_segments);
  Solver solver(test::context(), p.model, p.dt);
  REQUIRE(solver.fluid()->fused());
  const FluidCarriers* carriers = solver.cohesive()->fluid_carriers();
  REQUIRE(carriers != nullptr);
  size_t first = 0, last = 0;
  for (int check = 0; check < 8; ++check) {
    for (long k = 0; k < 200; ++k) solver.step(false);
    const auto broken = solver.cohesive()->broken();
    const auto damage = solver.cohesive()->damage();
    std::set<uint32_t> expected;
    for (size_t e = 0; e < broken.size(); ++e)
      if (broken[e] || damage[e] > 0) expected.insert(static_cast<uint32_t>(e));
    const cl_uint count = download<cl_uint>(test::context(), carriers->count, 1)[0];
    const auto list = download<cl_uint>(test::context(), carriers->list, count);
    const std::set<uint32_t> listed(list.begin(), list.end());
    CAPTURE(check);
    CHECK(listed.size() == list.size());  // no CE4 twice
    CHECK(listed == expected);
    if (check == 0) first = count;
    last = count;
  }
  CHECK(first > 0);
  CHECK(last > first + 6);  // the crack grew during the run (14 to 24 carriers on PoCL): the list grew with it
}

TEST_CASE("fluid: two runs give the same bits") {
  const PreparedCase p = sneddon(kCoarse);
  const auto a = run_steps(p, 150).positions;
  const auto b = run_steps(p, 150).positions;
  REQUIRE(a.size() == b.size());
  size_t differ = 0;
  for (size_t i = 0; i < a.size(); ++i) differ += a[i].x != b[i].x || a[i].y != b[i].y;
  CHECK(differ == 0);
}

TEST_CASE("fluid: bad [fluid] keys are refused with the file and the key, by check and run alike (exit 2)") {
  test::TempDir dir;
  std::string text;
  {
    std::ifstream in(test::source_path("cases/sneddon/case.toml"));
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  const size_t geo = text.find("geo = \"sneddon.geo\"");
  text.replace(geo, std::string("geo = \"sneddon.geo\"").size(), "geo = \"" + test::source_path("cases/sneddon/sneddon.geo") + "\"");
  struct Bad {
    std::string from, to, message;
  };
  const std::vector<Bad> bad{
      {"viscosity = 1.0", "viscosty = 1.0", "unknown key 'viscosty' in [fluid] (did you mean 'viscosity'?)"},
      {"viscosity = 1.0", "viscosity = -1.0", "fluid.viscosity"},
      {"viscosity = 1.0", "viscosity = 1.0\nleak_off = -1e-4", "fluid.leak_off"},
      {"viscosity = 1.0", "viscosity = 1.0\nleak_off = \"fast\"", "fluid.leak_off"},
      {"max_aperture = 2e-3", "max_aperture = 1e-8", "fluid.max_aperture"},
      {"source = \"crack\"", "source = \"crack\"\nrate = 1e-4", "fluid.rate and fluid.pressure are exclusive"},
      {"source = \"crack\"", "source = \"nowhere\"", "fluid.source"},
      {"source = \"crack\"", "source = \"outside\"", "fluid.source"},  // not on the crack: no room
  };
  for (const auto& b : bad) {
    std::string t = text;
    const size_t at = t.find(b.from);
    REQUIRE(at != std::string::npos);
    t.replace(at, b.from.size(), b.to);
    const std::string path = dir.write("bad.toml", t);
    CAPTURE(b.to);
    std::string message;
    try {
      (void)prepare_case(path, {"mesh.size=0.2", "output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      message = e.what();
    }
    CHECK(message.find(b.message) != std::string::npos);
    CHECK(message.find("bad.toml") != std::string::npos);
    for (const char* command : {"check", "run"}) {
      const auto [code, out] = run_fdem(std::string(command) + " " + path + " --set mesh.size=0.2 --set output.dir='\"" +
                                        dir.str() + "/out\"'");
      CAPTURE(out);
      CHECK(code == 2);
      CHECK(out.find(b.message) != std::string::npos);
    }
  }
}

TEST_CASE("fluid: fdem check reports the fluid's stable step and its sub-steps") {
  const auto [code, out] = run_fdem("check " + test::source_path("cases/sneddon/case.toml") +
                                    " --set mesh.size=0.2 --set output.dir='\"/tmp/fdem_test_fluid_out\"'");
  CAPTURE(out);
  CHECK(code == 0);
  CHECK(out.find("fluid dt") != std::string::npos);
  CHECK(out.find("sub-steps per step") != std::string::npos);
  const PreparedCase p = sneddon(kCoarse);
  CHECK(FluidFlow::substeps(p.model.fluid, p.dt) >= 1);
  CHECK(FluidFlow::substeps(p.model.fluid, 10 * p.model.fluid.stable_dt) == 20);  // safety 0.5
}

TEST_CASE("fluid: the fluid's spring in the mechanical step: fdem check reports it and warns when the step is above it") {
  // Sneddon without mass scaling: K_f = 1e9 Pa in a crack closed to w_r = 1e-7 m is far
  // stiffer than the rock; the KGD case (K_f 7e8, w_r 4e-5) is not.
  const std::string sneddon_case = test::source_path("cases/sneddon/case.toml");
  const std::string out = " --set output.dir='\"/tmp/fdem_test_fluid_out\"'";
  auto [code, text] = run_fdem("check " + sneddon_case + " --set mesh.size=0.2 --set damping.mass_scaling=false" + out);
  CAPTURE(text);
  CHECK(code == 0);
  CHECK(text.find("fluid k   the fluid's spring") != std::string::npos);
  CHECK(text.find("the case dt is above it") != std::string::npos);
  CHECK(text.find("warning: ") != std::string::npos);
  CHECK(text.find("fluid.bulk_modulus") != std::string::npos);
  // By hand for the CE4 it names: √(2 m / ((9/16) K_f h t / w_r)), m the lightest of its nodes.
  const PreparedCase p = sneddon({"mesh.size=0.2", "damping.mass_scaling=false", "output.dir=\"/tmp/fdem_test_fluid_out\""});
  const FluidSpring spring = fluid_spring(p.model);
  CHECK(p.dt > spring.dt);
  const size_t e = spring.ce4;
  const double k = 9.0 / 16.0 * 1e9 * p.model.fluid.segment_length[e] * p.model.thickness / 1e-7;
  CHECK(spring.dt < std::sqrt(2 * 2500.0 * 0.2 * 0.2 * p.model.thickness / k));  // lighter than a 0.2 m square's node
  auto [code2, text2] = run_fdem("check " + test::source_path("cases/kgd/viscosity.toml") + " --set mesh.size=0.2" + out);
  CAPTURE(text2);
  CHECK(code2 == 0);
  CHECK(text2.find("fluid k   the fluid's spring") != std::string::npos);
  CHECK(text2.find("the case dt is above it") == std::string::npos);
  CHECK(text2.find("fluid.bulk_modulus") == std::string::npos);
}

}  // TEST_SUITE
