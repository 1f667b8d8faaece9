// The contact stage's energy account end to end (issue 11): kinetic energy, gravity
// potential, strain energy, contact stored energy and the friction and damping
// dissipation must add up to the initial energy at every sampled step, in undamped and
// damped runs; and the undamped block must slide and stick as Coulomb says.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "approx.hpp"
#include "case_files.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

// One sampled step of the energy account [J].
struct EnergyRow {
  double time = 0;
  double kinetic = 0, gravity = 0, strain = 0, stored = 0, friction = 0, damping = 0;
  double disp_x = 0;  // mean x displacement of the free nodes [m]
  double total() const { return kinetic + gravity + strain + stored + friction + damping; }
};

std::ostream& operator<<(std::ostream& out, const EnergyRow& r) {
  return out << "t " << r.time << ": kinetic " << r.kinetic << ", gravity " << r.gravity << ", strain " << r.strain
             << ", contact stored " << r.stored << ", friction " << r.friction << ", damping " << r.damping
             << ", total " << r.total();
}

// Steps a case on a Solver and samples the account. The leapfrog's velocities live at
// half steps: the kinetic energy of step n is the mean of the two half-step values
// around it (the estimate whose change is exactly the forces' work), read before and
// after an energy-row step; gravity potential −m g·(x − x0) and the strain energy at
// the step's positions; the contact terms from the stage at the same step.
class EnergyRun {
 public:
  EnergyRun(const std::string& case_path, const std::vector<std::string>& overrides)
      : prepared_(prepare_case(case_path, overrides)), solver_(test::context(), prepared_.model, prepared_.dt) {
    for (const auto& mk : solver_.masses()) mass_.push_back(mk.x);
    x0_ = solver_.positions();
    for (size_t i = 0; i < prepared_.model.num_nodes(); ++i)
      free_.push_back(prepared_.model.groups[prepared_.model.node_group[i]].mask == 0);
  }
  double dt() const { return prepared_.dt; }

  EnergyRow sample() {
    const auto x = solver_.positions();
    const auto v_before = solver_.velocities();
    solver_.contact()->request_energy_row();
    solver_.step();
    const auto v_after = solver_.velocities();
    EnergyRow r;
    r.time = solver_.time() - solver_.dt();
    const auto g = prepared_.model.gravity;
    double free_nodes = 0;
    for (size_t i = 0; i < x.size(); ++i) {
      const double k0 = double(v_before[i].x) * v_before[i].x + double(v_before[i].y) * v_before[i].y;
      const double k1 = double(v_after[i].x) * v_after[i].x + double(v_after[i].y) * v_after[i].y;
      r.kinetic += 0.25 * mass_[i] * (k0 + k1);
      r.gravity -= mass_[i] * (g[0] * (x[i].x - x0_[i].x) + g[1] * (x[i].y - x0_[i].y));
      if (free_[i]) r.disp_x += x[i].x - x0_[i].x, free_nodes += 1;
    }
    r.disp_x /= free_nodes;
    r.strain = strain_energy(x);
    auto& c = *solver_.contact();
    r.stored = c.stored_energy();
    r.friction = c.friction_dissipation();
    r.damping = c.damping_dissipation();
    return r;
  }

  // Runs to `end` [s], sampling every `every` steps from step 0.
  std::vector<EnergyRow> run(double end, long every) {
    std::vector<EnergyRow> rows;
    const long steps = std::lround(end / prepared_.dt);
    while (solver_.steps_done() < steps) {
      rows.push_back(sample());
      for (long k = 1; k < every && solver_.steps_done() < steps; ++k) solver_.step();
    }
    REQUIRE(solver_.conditions().ok());
    return rows;
  }

 private:
  // Strain energy of the triangles, St Venant–Kirchhoff W = λ/2 (tr E)² + μ E:E with the
  // Green strain from displacement differences (no cancellation). At the strains of
  // these runs (≤ 1e-3) it is the Neo-Hookean energy of Eq. 1 to O(ε³).
  double strain_energy(const std::vector<real2>& x) const {
    const auto& m = prepared_.model;
    double total = 0;
    for (size_t t = 0; t < m.num_triangles(); ++t) {
      const auto& tri = m.triangles[t];
      const auto& mat = m.materials[m.triangle_material[t]];
      const double X00 = m.x[tri[1]] - m.x[tri[0]], X01 = m.x[tri[2]] - m.x[tri[0]];
      const double X10 = m.y[tri[1]] - m.y[tri[0]], X11 = m.y[tri[2]] - m.y[tri[0]];
      const double det = X00 * X11 - X01 * X10;
      auto u = [&](int a, int c) { return c == 0 ? x[tri[a]].x - x0_[tri[a]].x : x[tri[a]].y - x0_[tri[a]].y; };
      const double U00 = u(1, 0) - u(0, 0), U01 = u(2, 0) - u(0, 0), U10 = u(1, 1) - u(0, 1), U11 = u(2, 1) - u(0, 1);
      const double H00 = (U00 * X11 - U01 * X10) / det, H01 = (-U00 * X01 + U01 * X00) / det;  // H = U X⁻¹
      const double H10 = (U10 * X11 - U11 * X10) / det, H11 = (-U10 * X01 + U11 * X00) / det;
      const double E00 = H00 + 0.5 * (H00 * H00 + H10 * H10), E11 = H11 + 0.5 * (H01 * H01 + H11 * H11);
      const double E01 = 0.5 * (H01 + H10 + H00 * H01 + H10 * H11);
      const double W = 0.5 * mat.lambda * (E00 + E11) * (E00 + E11) + mat.mu * (E00 * E00 + E11 * E11 + 2 * E01 * E01);
      total += W * 0.5 * std::fabs(det) * m.thickness;
    }
    return total;
  }

  PreparedCase prepared_;
  Solver solver_;
  std::vector<double> mass_;
  std::vector<real2> x0_;
  std::vector<bool> free_;
};

// The largest |total − initial| over the rows, and the row where it is.
std::pair<double, size_t> worst_imbalance(const std::vector<EnergyRow>& rows) {
  std::pair<double, size_t> worst{0, 0};
  for (size_t k = 0; k < rows.size(); ++k)
    worst = std::max(worst, {std::fabs(rows[k].total() - rows[0].total()), k});
  return worst;
}

// Least-squares acceleration of x(t) = x0 + v0 t + a t²/2 over the rows' second half.
double fitted_acceleration(const std::vector<EnergyRow>& rows) {
  const size_t first = rows.size() / 2, n = rows.size() - first;
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (size_t k = 0; k < n; ++k) {
    const double t = rows[first + k].time;
    A.row(k) << 1.0, t, 0.5 * t * t;
    b(k) = rows[first + k].disp_x;
  }
  return A.colPivHouseholderQr().solve(b)(2);
}

std::string incline_gravity(double degrees) {
  const double a = degrees * M_PI / 180;
  std::ostringstream text;
  text.precision(17);
  text << "gravity.g=[" << 9.81 * std::sin(a) << ", " << -9.81 * std::cos(a) << "]";
  return text.str();
}

}  // namespace

TEST_SUITE("contact") {

TEST_CASE("undamped sliding block: stops within 2% of v²/(2μg), and its energy account closes within 1% at every step") {
  if (!kDoublePrecision) {  // the block's overlaps (nm) are below float resolution at metres
    MESSAGE("skipped in the float build");
    return;
  }
  // cases/sliding/undamped.toml: no viscosity, no contact damping; 1 m/s keeps it short.
  const double v = 1.0, mu = 0.5, g = 9.81;
  EnergyRun run(test::source_path("cases/sliding/undamped.toml"), {"initial.0.velocity=[1.0, 0.0]"});
  const auto rows = run.run(v / (mu * g) + 0.04, 400);
  const double expected = v * v / (2 * mu * g), initial = rows[0].total();
  const auto [worst, at] = worst_imbalance(rows);
  MESSAGE("slide " << rows.back().disp_x << " m against v²/(2μg) = " << expected << " m ("
                   << 100 * (rows.back().disp_x / expected - 1) << "%); largest imbalance " << worst << " J of "
                   << initial << " J at " << rows[at]);
  MESSAGE("last row " << rows.back());
  CHECK(rows.back().disp_x == test::rel(expected, 0.02));
  CHECK(worst < 0.01 * initial);
  CHECK(rows.back().kinetic < 0.01 * initial);            // it has stopped
  CHECK(rows.back().friction > 0.95 * initial);           // friction took the energy, not numerics
  double drop = 0;
  size_t drop_at = 0;
  for (size_t k = 1; k < rows.size(); ++k)
    if (rows[k - 1].friction - rows[k].friction > drop) drop = rows[k - 1].friction - rows[k].friction, drop_at = k;
  MESSAGE("largest drop of the friction account " << drop << " J at " << rows[drop_at]);
  // The account may step back by round-off: a couple that lets go books its last half
  // step's trapezoid work, which can be negative while the stopped block rocks. Measured:
  // no drop with the mesh file's numbering, 1.0e-8 J (4.4e-9 × initial) with the Hilbert
  // numbering (mesh.order), whose couples pair the triangles the other way round.
  for (size_t k = 1; k < rows.size(); ++k) CHECK(rows[k].friction >= rows[k - 1].friction - 1e-8 * initial);
  CHECK(rows.back().damping == 0);
}

TEST_CASE("undamped block on an incline: at 0.9 × the friction angle it creeps < 0.05 mm in 0.2 s; at 1.5 × it slides with a = g(sin θ − μ cos θ)") {
  if (!kDoublePrecision) {  // the block's overlaps (nm) are below float resolution at metres
    MESSAGE("skipped in the float build");
    return;
  }
  const double friction_angle = std::atan(0.4) * 180 / M_PI;
  {
    EnergyRun run(test::source_path("cases/sliding/incline.toml"), {incline_gravity(0.9 * friction_angle)});
    const auto rows = run.run(0.2, 2000);
    const auto [worst, at] = worst_imbalance(rows);
    double creep = 0;
    for (const auto& r : rows) creep = std::max(creep, std::fabs(r.disp_x));
    MESSAGE("0.9 × friction angle: creep " << creep << " m in 0.2 s; largest imbalance " << worst << " J at " << rows[at]);
    CHECK(creep < 0.05e-3);
    CHECK(worst < 0.01 * 4.5 * 9.81 * 0.05e-3 + 1e-6);  // a tiny energy scale: 1% of m g × 0.05 mm
  }
  {
    const double theta = 1.5 * std::atan(0.4);
    EnergyRun run(test::source_path("cases/sliding/incline.toml"), {incline_gravity(1.5 * friction_angle)});
    const auto rows = run.run(0.2, 2000);
    const double a = fitted_acceleration(rows), expected = 9.81 * (std::sin(theta) - 0.4 * std::cos(theta));
    const auto [worst, at] = worst_imbalance(rows);
    MESSAGE("1.5 × friction angle: a = " << a << " m/s² against " << expected << "; largest imbalance " << worst
                                         << " J at " << rows[at]);
    CHECK(a == doctest::Approx(expected).epsilon(0.03));
    CHECK(worst < 0.01 * std::fabs(rows.back().gravity));
  }
}

TEST_CASE("block creeping on an incline: friction books the gravity work it takes to 0.1% at every row, though each couple dissipates less than the accumulator's unit a step") {
  if (!kDoublePrecision) {  // the block's overlaps (nm) are below float resolution at metres
    MESSAGE("skipped in the float build");
    return;
  }
  // At 0.9 × the friction angle the undamped block rocks (4 to 9 touching couples) and
  // ratchets down ~3 µm in 0.05 s. Each couple's friction dissipation of a step is ~3e-10
  // J, about the 2⁻³² J unit of the fixed-point accumulator: rounding every increment to
  // the nearest unit lost 1.1% of the work (the account was 1.1% short at every row).
  const double friction_angle = std::atan(0.4) * 180 / M_PI;
  EnergyRun run(test::source_path("cases/sliding/incline.toml"), {incline_gravity(0.9 * friction_angle)});
  // Allowed: 0.1% of the gravity work, + 1e-9 J for what the couples carry unbooked at a
  // row (under half a unit each, 9 couples at most).
  const auto rows = run.run(0.05, 500);
  double worst = 0;
  size_t at = 1;
  for (size_t k = 1; k < rows.size(); ++k) {
    const double share = std::fabs(rows[k].total() - rows[0].total()) / (1e-3 * std::fabs(rows[k].gravity) + 1e-9);
    if (share > worst) worst = share, at = k;
  }
  MESSAGE("largest imbalance " << worst << " of the allowance at " << rows[at] << "; last row " << rows.back());
  CHECK(std::fabs(rows.back().gravity) > 3e-5);  // it crept: the friction did work
  CHECK(rows.back().friction > 0.95 * std::fabs(rows.back().gravity));
  CHECK(worst < 1);
}

TEST_CASE("disc impact: b = 1 conserves kinetic + strain + contact stored energy within 1% at every step; b = 2 loses what contact_damping_dissipation says") {
  const std::string impact = test::source_path("cases/impact/case.toml");
  for (double b : {1.0, 2.0}) {
    CAPTURE(b);
    std::ostringstream damping;
    damping << "contact.damping={exponent=" << b << "}";
    EnergyRun run(impact, {"mesh.size=0.02", damping.str()});
    const auto rows = run.run(0.0016, 20);
    const double initial = rows[0].total();
    const auto [worst, at] = worst_imbalance(rows);
    MESSAGE("b = " << b << ": largest imbalance " << worst << " J of " << initial << " J at " << rows[at]);
    MESSAGE("last row " << rows.back());
    double peak_stored = 0;
    for (const auto& r : rows) peak_stored = std::max(peak_stored, r.stored);
    CHECK(peak_stored > 0.5 * initial);  // the account was tested while the contact held most of the energy
    CHECK(worst < 0.01 * initial);
    CHECK(rows.back().stored == 0);  // bounced off
    for (size_t k = 1; k < rows.size(); ++k) CHECK(rows[k].damping >= rows[k - 1].damping - 1e-9 * initial);
    if (b == 1.0) {
      CHECK(rows.back().damping == 0);
      CHECK(rows.back().kinetic > 0.99 * initial);
    } else {
      const double lost = initial - rows.back().kinetic - rows.back().strain;
      CHECK(rows.back().damping > 0.1 * initial);
      CHECK(std::fabs(lost - rows.back().damping) < 0.01 * initial);
    }
  }
}

}  // TEST_SUITE
