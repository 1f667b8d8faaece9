// [fluid.gas]: the explosion products of a blast hole, a polytropic gas that pushes the
// hole's wall and flows into the cracks (engine/stages/fluid_flow.*, cl_kernels/fluid_flow.cl
// gas_hole_state; issue 32's gas verification). tests/data/cases/gas_small.toml: the small
// blast (744 TRI3) with the hole filled at 1 GPa, about a second on PoCL.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "base/errors.hpp"
#include "case_files.hpp"
#include "fdem_cli.hpp"
#include "engine/run/prepare_case.hpp"
#include "engine/stages/fluid_flow.hpp"
#include "approx.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

const char* kGasCase = "tests/data/cases/gas_small.toml";

// gas_small.toml's text with its mesh path made absolute (written elsewhere, it still finds it).
std::string gas_case_text() {
  std::ifstream in(test::source_path(kGasCase));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string file = "file = \"blast_small.msh\"";
  text.replace(text.find(file), file.size(),
               "file = \"" + test::source_path("tests/data/cases/blast_small.msh") + "\"");
  return text;
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

}  // namespace

TEST_SUITE("fluid") {

TEST_CASE("fluid gas: the small blast keeps its gas (hole + cracks), the hole's pressure falls as the cracks fill, "
          "energy closes within 1%") {
  test::TempDir tmp;
  const PreparedCase p = prepare_case(test::source_path(kGasCase),
                                      {"output.dir=\"" + tmp.str() + "/gas\"", "output.history_every=1e-5"});
  REQUIRE(p.model.fluid.gas);
  const double rho0 = 1200.0, p0 = 1e9, gamma = 3.0;
  // The hole: a 16-sided polygon (8 wall edges, each split at nothing yet) of the 0.05 m circle.
  CHECK(p.model.fluid.hole_volume == doctest::Approx(M_PI * 0.05 * 0.05).epsilon(0.15));
  CHECK(p.model.fluid.source_vertices.size() == 8);
  test::run(p);
  const std::string h = tmp.str() + "/gas/gas_history.nc";
  const auto hole_mass = test::read_variable(h, "hole_gas_mass");
  const auto network_mass = test::read_variable(h, "network_gas_mass");
  const auto hole_p = test::read_variable(h, "hole_pressure");
  const auto hole_v = test::read_variable(h, "hole_volume");
  const auto broken = test::read_variable(h, "broken_ce4");
  const auto error = test::read_variable(h, "energy_error");
  const auto dissipated = test::read_variable(h, "fluid_viscous_dissipation");
  REQUIRE(hole_mass.size() >= 15);
  // Mass: what the hole held at ρ0 is in the hole or the cracks, to rounding (issue: 0.1%).
  const double m0 = rho0 * p.model.fluid.hole_volume;
  double worst = 0;
  for (size_t k = 0; k < hole_mass.size(); ++k) worst = std::max(worst, std::fabs(hole_mass[k] + network_mass[k] - m0) / m0);
  CHECK(worst < 1e-12);
  // The cracks take the gas: half of it by 0.2 ms, and the hole's pressure follows its
  // state law from what is left and the hole's volume at every row.
  CHECK(network_mass.back() > 0.4 * m0);
  CHECK(broken.back() > 100);
  for (size_t k = 0; k < hole_p.size(); ++k) {
    CAPTURE(k);
    CHECK(hole_p[k] == doctest::Approx(p0 * std::pow(hole_mass[k] / (rho0 * hole_v[k]), gamma)).epsilon(1e-9));
  }
  CHECK(hole_v.back() > p.model.fluid.hole_volume);  // the wall moved out
  CHECK(hole_p.back() < 0.1 * p0);
  for (size_t k = 1; k < hole_p.size(); ++k) CHECK(hole_p[k] < hole_p[k - 1]);  // falls all along
  // The account: the throttling and free expansion are booked (a large share), and it closes.
  CHECK(dissipated.back() > 0);
  CAPTURE(max_abs(error));
  CHECK(max_abs(error) < 0.01);
}

TEST_CASE("fluid gas: the mid-step pressure makes the coupling second order: halving the step more than halves "
          "the energy error") {
  test::TempDir tmp;
  auto worst = [&](const char* out, const char* safety) {
    test::run(test::source_path(kGasCase), {"output.dir=\"" + tmp.str() + "/" + out + "\"", "time.end=1e-4",
                                            std::string("time.safety=") + safety});
    return max_abs(test::read_variable(tmp.str() + "/" + out + "/gas_history.nc", "energy_error"));
  };
  const double coarse = worst("a", "0.5"), fine = worst("b", "0.25");
  CAPTURE(coarse);
  CAPTURE(fine);
  CHECK(coarse < 0.01);
  CHECK(fine < 0.7 * coarse);
}

TEST_CASE("fluid gas: a run to T and a run to T/2 restarted to T give the same history (the hole's gas is in the "
          "checkpoint)") {
  test::TempDir tmp;
  auto sets = [&](const std::string& out, const char* end) {
    return std::vector<std::string>{"output.dir=\"" + tmp.str() + "/" + out + "\"", std::string("time.end=") + end,
                                    "output.history_every=1e-5"};
  };
  const std::string path = test::source_path(kGasCase);
  test::run(path, sets("one", "1e-4"));
  test::run(path, sets("two", "5e-5"));
  test::run(path, sets("two", "1e-4"), test::restart_from(tmp.str() + "/two/gas.ckpt"));
  for (const char* name : {"hole_pressure", "hole_volume", "hole_gas_mass", "network_gas_mass", "broken_ce4",
                           "fluid_viscous_dissipation", "energy_error"}) {
    CAPTURE(name);
    const auto d = test::compare_variable(tmp.str() + "/one/gas_history.nc", tmp.str() + "/two/gas_history.nc", name);
    REQUIRE(d.rows_a == d.rows_b);
    CHECK(d.differ == 0);
  }
}

TEST_CASE("fluid gas: the group kernel's size does not change a bit (256 and 1024 work-items)") {
  // A GPU takes 1024 work-items for the gas's sub-steps, a CPU device 256
  // (FDEM_FLUID_GROUP_SIZE sets it): each vertex's sub-step is the same whichever item does it.
  test::TempDir tmp;
  struct Unset {
    ~Unset() { unsetenv("FDEM_FLUID_GROUP_SIZE"); }
  } unset;
  const std::string path = test::source_path(kGasCase);
  for (const char* size : {"256", "1024"}) {
    setenv("FDEM_FLUID_GROUP_SIZE", size, 1);
    test::run(path, {"output.dir=\"" + tmp.str() + "/g" + size + "\"", "time.end=1e-4", "output.history_every=1e-5"});
  }
  for (const char* name : {"hole_pressure", "hole_gas_mass", "network_gas_mass", "broken_ce4", "fluid_face_work",
                           "fluid_viscous_dissipation", "energy_error"}) {
    CAPTURE(name);
    const auto d = test::compare_variable(tmp.str() + "/g256/gas_history.nc", tmp.str() + "/g1024/gas_history.nc", name);
    REQUIRE(d.rows_a == d.rows_b);
    REQUIRE(d.rows_a >= 10);
    CHECK(d.differ == 0);
  }
}

TEST_CASE("fluid gas: the faces' forces are the gradient of the gas's p V, also where a face has turned over") {
  // Every CE4 of the small blast broken (so every one carries gas), the nodes moved at
  // random, and one wall segment's second face turned over and carried 5 cm off (its faces
  // antiparallel: a chord of zero length, which the chord's normal could not take). One
  // step of the stage; then per CE4 the four slots against a central difference of
  // p_a V_a + p_b V_b, the halves' rooms in plain C++ (V = (h/2) t w(A / (h/2)), A the
  // area between the half faces, w the smooth aperture), at the pressures the kernel's
  // forces took (the mid-step room from vertex_rate); the vertices' rooms against the same.
  test::TempDir tmp;  // its own folder: a fixed one is shared with any other run of the suite
  const PreparedCase p = prepare_case(test::source_path(kGasCase), {"output.dir=\"" + tmp.str() + "/grad\""});
  const Model& m = p.model;
  const FluidModel& f = m.fluid;
  REQUIRE(f.gas);
  auto& cl = test::context();
  const size_t n_ce4 = m.ce4.size();
  std::vector<cl_int2> status(n_ce4, cl_int2{{1, 1}});
  std::vector<real> gauss(9 * n_ce4);  // three reals per Gauss point (CohesiveForces::gauss_state)
  compute::buffer position(cl.context(), m.num_nodes() * sizeof(real2));
  compute::buffer status_buffer(cl.context(), n_ce4 * sizeof(cl_int2));
  compute::buffer gauss_buffer(cl.context(), 9 * n_ce4 * sizeof(real));
  upload(cl, status_buffer, status);
  upload(cl, gauss_buffer, gauss);
  {  // the mesh's positions first, as the solver has them when it makes the stage (its hole's gas)
    std::vector<real2> x0(m.num_nodes());
    for (size_t n = 0; n < m.num_nodes(); ++n) x0[n] = {real(m.x[n]), real(m.y[n])};
    upload(cl, position, x0);
  }
  FluidFlow stage(cl, m, position, status_buffer, gauss_buffer, p.dt);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x(2 * m.num_nodes());
  for (size_t n = 0; n < m.num_nodes(); ++n) x[2 * n] = m.x[n] + 2e-4 * u(rng), x[2 * n + 1] = m.y[n] + 2e-4 * u(rng);
  // The turned-over segment: one with an end on the hole's wall (full of gas after the step).
  size_t flipped = n_ce4;
  for (size_t e = 0; e < n_ce4 && flipped == n_ce4; ++e)
    if (std::binary_search(f.source_vertices.begin(), f.source_vertices.end(), f.segment_vertex[2 * e]))
      flipped = e;
  REQUIRE(flipped < n_ce4);
  {
    const auto& nd = m.ce4[flipped];  // i' over j and j' over i, 5 cm along +x
    x[2 * nd[3]] = x[2 * nd[1]] + 0.05, x[2 * nd[3] + 1] = x[2 * nd[1] + 1];
    x[2 * nd[2]] = x[2 * nd[0]] + 0.05, x[2 * nd[2] + 1] = x[2 * nd[0] + 1];
  }
  std::vector<real2> xr(m.num_nodes());
  for (size_t n = 0; n < m.num_nodes(); ++n) xr[n] = {real(x[2 * n]), real(x[2 * n + 1])};
  upload(cl, position, xr);
  stage.enqueue(0.0, 0);
  const auto state = stage.vertex_state();
  const auto rate = stage.vertex_rate();
  const auto slots = download<real2>(cl, stage.slots(), 4 * n_ce4);

  const double t = m.thickness, wr = f.residual_aperture;
  auto aperture = [wr](double o) { return o / wr > 30 ? o : wr * std::log1p(std::exp(o / wr)); };
  auto area = [](const double* p0, const double* p1, const double* p2, const double* p3) {
    const double d1x = p2[0] - p0[0], d1y = p2[1] - p0[1], d2x = p3[0] - p1[0], d2y = p3[1] - p1[1];
    return 0.5 * (d2x * d1y - d2y * d1x);
  };
  // The rooms of CE4 e's two halves from its four corners (i, j, j', i').
  auto rooms = [&](size_t e, const std::array<std::array<double, 2>, 4>& c) {
    const double h2 = 0.5 * f.segment_length[e];
    const double m1[2] = {0.5 * (c[0][0] + c[1][0]), 0.5 * (c[0][1] + c[1][1])};
    const double m2[2] = {0.5 * (c[3][0] + c[2][0]), 0.5 * (c[3][1] + c[2][1])};
    return std::array<double, 2>{h2 * t * aperture(area(c[0].data(), m1, m2, c[3].data()) / h2),
                                 h2 * t * aperture(area(m1, c[1].data(), c[2].data(), m2) / h2)};
  };
  auto corners = [&](size_t e) {
    std::array<std::array<double, 2>, 4> c;
    for (int k = 0; k < 4; ++k) c[k] = {x[2 * m.ce4[e][k]], x[2 * m.ce4[e][k] + 1]};
    return c;
  };
  auto pressure = [&](uint32_t v) {  // gas_pressure at mid_step_volume, as fluid_forces
    const double room = state[v].y + std::clamp(0.5 * rate[v], -0.25 * state[v].y, 0.25 * state[v].y);
    const double v0 = state[v].x;
    if (!(room > 0 && v0 > 0)) return 0.0;
    return v0 >= room ? f.gas_pressure : f.gas_pressure * std::pow(v0 / room, f.gamma);
  };
  std::vector<double> volume(f.vertices, 0.0);
  double scale = 0, worst = 0;
  std::vector<std::array<double, 2>> reference(4 * n_ce4);
  for (size_t e = 0; e < n_ce4; ++e) {
    const uint32_t a = f.segment_vertex[2 * e], b = f.segment_vertex[2 * e + 1];
    const auto c = corners(e);
    const auto v = rooms(e, c);
    volume[a] += v[0], volume[b] += v[1];
    const double pa = pressure(a), pb = pressure(b);
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 2; ++d) {
        const double step = 1e-9;
        auto plus = c, minus = c;
        plus[k][d] += step, minus[k][d] -= step;
        const auto vp = rooms(e, plus), vm = rooms(e, minus);
        reference[4 * e + k][d] = (pa * (vp[0] - vm[0]) + pb * (vp[1] - vm[1])) / (2 * step);
        scale = std::max(scale, std::fabs(reference[4 * e + k][d]));
      }
  }
  double flipped_force = 0;
  for (size_t k = 0; k < slots.size(); ++k) {
    const double got[2] = {slots[k].x, slots[k].y};
    for (int d = 0; d < 2; ++d) {
      REQUIRE(std::isfinite(got[d]));
      worst = std::max(worst, std::fabs(got[d] - reference[k][d]));
      if (k / 4 == flipped) flipped_force = std::max(flipped_force, std::fabs(got[d]));
    }
  }
  double room_worst = 0;
  for (size_t v = 0; v < f.vertices; ++v)
    room_worst = std::max(room_worst, std::fabs(state[v].y - volume[v]) / std::max(volume[v], 1e-30));
  CAPTURE(scale);
  CAPTURE(worst / scale);
  CAPTURE(room_worst);
  CAPTURE(flipped_force);
  MESSAGE("gas forces against the gradient: worst " << worst / scale << " of the largest, rooms " << room_worst
                                                      << ", turned-over segment " << flipped_force << " N");
  CHECK(scale > 0);
  CHECK(worst <= (kDoublePrecision ? 1e-5 : 1e-2) * scale);
  CHECK(room_worst <= (kDoublePrecision ? 1e-12 : 1e-5));
  // The turned-over segment: no room between its faces (antiparallel, their quads' areas
  // cancel), so a force of at most p0 t times its face's length, not the 1/|chord| blow-up.
  CHECK(flipped_force > 0);
  CHECK(flipped_force <= f.gas_pressure * t * 2 * f.segment_length[flipped]);
}

TEST_CASE("fluid gas: bad [fluid.gas] keys and holes are refused with the file and the key (exit 2)") {
  test::TempDir dir;
  const std::string text = gas_case_text();
  struct Bad {
    std::string from, to, message;
  };
  const std::vector<Bad> bad{
      {"gamma = 3.0", "gamma = 1.0", "fluid.gas.gamma"},
      {"gamma = 3.0", "gama = 3.0", "unknown key 'gama' in fluid.gas (did you mean 'gamma'?)"},
      {"density = 1200.0", "density = -1.0", "fluid.gas.density"},
      {"pressure = 1.0e9", "pressure = 0.0", "fluid.gas.pressure"},
      {"hole = \"hole\"", "hole = \"nowhere\"", "fluid.gas.hole"},
      {"hole = \"hole\"\n[[boundary]]\nregion = \"outer\"\nabsorbing = true", "hole = \"outer\"", "does not enclose a hole"},
      {"hole = \"hole\"", "hole = \"outer\"", "boundary[0] loads region 'outer', the hole of [fluid.gas]"},
      {"hole = \"hole\"", "hole = \"rock\"", "act on a physical curve"},
      {"viscosity = 1e-3", "viscosity = 1e-3\nbulk_modulus = 2e9", "fluid.bulk_modulus is not allowed with [fluid.gas]"},
      {"viscosity = 1e-3", "viscosity = 1e-3\nleak_off = 1e-4", "no leak-off for the gas"},
      {"aperture_limit = \"cap\"", "aperture_limit = \"clip\"", "fluid.aperture_limit"},
      {"[[boundary]]\nregion = \"outer\"", "[[boundary]]\nregion = \"hole\"\npressure = 1e6\n[[boundary]]\nregion = \"outer\"",
       "the hole of [fluid.gas]"},
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
      (void)prepare_case(path, {"output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      message = e.what();
    }
    CAPTURE(message);
    CHECK(message.find(b.message) != std::string::npos);
    CHECK(message.find("bad.toml") != std::string::npos);
    const auto [code, out] = test::run_fdem_cli("check " + path + " --set output.dir='\"" + dir.str() + "/out\"'");
    CAPTURE(out);
    CHECK(code == 2);
    CHECK(out.find(b.message) != std::string::npos);
  }
}

TEST_CASE("fluid gas: fdem check names the gas, its hole and the sub-steps") {
  const auto [code, out] = test::run_fdem_cli("check " + test::source_path(kGasCase) + " --set output.dir='\"/tmp/fdem_test_gas_out\"'");
  CAPTURE(out);
  CHECK(code == 0);
  CHECK(out.find("gas       gamma 3, rho0 1200 kg/m3, p0 1e+09 Pa in hole 'hole' (0.00707107 m3, 8.48528 kg") != std::string::npos);
  CHECK(out.find("sub-steps per step") != std::string::npos);
}

}  // TEST_SUITE
