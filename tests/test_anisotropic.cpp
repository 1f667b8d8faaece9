// Anisotropic elasticity end to end (issue 5, part 5): an orthotropic sample whose
// material axes are turned by 30°, under uniaxial stress, relaxed to static equilibrium,
// against the closed-form small-strain answer ε = S σ from the compliance rotated into
// the global frame. The reference rotates the stress into the material frame and the
// strain back (2×2 tensors), not the stiffness (engine/model/materials.cpp rotates the
// 4th-order stiffness), so the two paths are independent.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "approx.hpp"
#include "case_files.hpp"
#include "engine/run/run.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

// A 0.4 m × 0.2 m rectangle: left edge on rollers (x held), the bottom-left corner held
// in y, traction σ on the right edge, top and bottom free. With those supports the
// uniform field u_x = ε_xx x, u_y = γ_xy x + ε_yy y (uniaxial stress plus a rigid
// rotation) satisfies every boundary condition, so the exact solution is uniform and a
// TRI3 mesh represents it exactly: any error is the constitutive path's.
const char* kSampleGeo = R"(If(!Exists(size)) size = 0.05; EndIf
Point(1) = {0, 0, 0, size};
Point(2) = {0.4, 0, 0, size};
Point(3) = {0.4, 0.2, 0, size};
Point(4) = {0, 0.2, 0, size};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("sample") = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Point("corner") = {1};
)";

// Material-frame constants [Pa] (orthotropic: c16 = c26 = 0) and the angle of the 1 axis.
constexpr double kC11 = 60e9, kC22 = 20e9, kC12 = 8e9, kC66 = 10e9, kAngle = 30.0;
// σ_xx [Pa]: strains ~3e-5. The dead load stays along x while the sample shears by γ,
// an O(γ) out-of-balance that bends it slightly: ±0.025% in σ_xx at 1 MPa (±0.25% at
// 10 MPa), so a small load keeps the check on the constitutive path. A float build
// cannot relax such small strains (position increments fall below an ulp; measured
// 11% off in γ at 1 MPa): there 10 MPa, 20,000 steps and 2% (measured 0.27%, σ_xx
// within ±0.6%).
constexpr double kTraction = kDoublePrecision ? 1e6 : 10e6;
constexpr long kSteps = kDoublePrecision ? 4000 : 20000;
constexpr double kTolerance = kDoublePrecision ? 0.005 : 0.02;

// True masses and local damping relax it: with mass scaling (inertia 0.3 Δt² Σk) and
// α = 0.8 this sample diverges, because for these constants ω²Δt² reaches 2.57 and the
// local damping scales the force by up to 1 + α when it opposes the velocity
// (2.57 × 1.8 > 4); α ≤ 0.5 converges (cases/anisotropic/README.md). That is the
// mass-scaling bound, not the anisotropic stress, and is left to the mass-scaling code.
std::string sample_case(const std::string& geo, const std::string& out) {
  std::ostringstream c;
  c << "title = \"anisotropic uniaxial stretch\"\n[mesh]\ngeo = \"" << geo << "\"\nsize = 0.05\n"
    << "[time]\ndt = \"auto\"\nsteps = " << kSteps << "\n[output]\ndir = \"" << out << "\"\nframes = 2\n"
    << "[[material]]\nname = \"slate\"\nregions = [\"sample\"]\ndensity = 2700.0\nyoung = 40e9\npoisson = 0.2\n"
    << "elasticity = \"hyperelastic\"\n"
    << "stiffness = { c11 = " << kC11 << ", c22 = " << kC22 << ", c12 = " << kC12 << ", c66 = " << kC66
    << ", angle = " << kAngle << " }\n"
    << "[damping]\nlocal = 0.8\n"
    << "[[boundary]]\nregion = \"left\"\nfix = [\"x\"]\n"
    << "[[boundary]]\nregion = \"corner\"\nfix = [\"y\"]\n"
    << "[[boundary]]\nregion = \"right\"\ntraction = [" << kTraction << ", 0.0]\n";
  return c.str();
}

// Closed form: ε (xx, yy, engineering γxy) under σ = (σxx, 0, 0).
Eigen::Vector3d closed_form_strain(double sxx) {
  Eigen::Matrix3d C;
  C << kC11, kC12, 0, kC12, kC22, 0, 0, 0, kC66;
  const Eigen::Matrix3d S = C.inverse();  // material-frame compliance
  const double a = kAngle * M_PI / 180.0;
  Eigen::Matrix2d R;  // columns: the material 1 and 2 axes in the global frame
  R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  Eigen::Matrix2d sigma;
  sigma << sxx, 0, 0, 0;
  const Eigen::Matrix2d sm = R.transpose() * sigma * R;
  const Eigen::Vector3d em = S * Eigen::Vector3d(sm(0, 0), sm(1, 1), sm(0, 1));
  Eigen::Matrix2d eps_m;
  eps_m << em(0), 0.5 * em(2), 0.5 * em(2), em(1);
  const Eigen::Matrix2d eps = R * eps_m * R.transpose();
  return {eps(0, 0), eps(1, 1), 2 * eps(0, 1)};
}

}  // namespace

TEST_SUITE("anisotropic") {

TEST_CASE("orthotropic sample at 30° under uniaxial stretch: strains match the rotated compliance within 0.5%") {
  test::TempDir dir;
  const std::string geo = dir.write("sample.geo", kSampleGeo);
  const std::string path = dir.write("sample.toml", sample_case(geo, dir.str() + "/out"));
  test::run(path);
  const std::string exo = dir.str() + "/out/sample.exo";

  // Displacement gradient G by least squares over every node: u = u0 + G X.
  const auto X = test::read_variable(exo, "coordx"), Y = test::read_variable(exo, "coordy");
  const auto ux_all = test::read_variable(exo, "vals_nod_var1"), uy_all = test::read_variable(exo, "vals_nod_var2");
  const size_t n = X.size();
  REQUIRE(ux_all.size() == 2 * n);  // two frames
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd ux(n), uy(n);
  for (size_t i = 0; i < n; ++i) {
    A.row(i) << 1.0, X[i], Y[i];
    ux(i) = ux_all[n + i];
    uy(i) = uy_all[n + i];
  }
  const Eigen::Vector3d gx = A.colPivHouseholderQr().solve(ux), gy = A.colPivHouseholderQr().solve(uy);
  const Eigen::Vector3d measured(gx(1), gy(2), gx(2) + gy(1));
  const Eigen::Vector3d exact = closed_form_strain(kTraction);
  MESSAGE("strain (xx, yy, γxy): measured " << measured.transpose() << ", closed form " << exact.transpose());
  // The closed form for these constants: (2.9313e-5, -9.947e-6, -1.8601e-5); each
  // component is sizeable, so each is checked against its own magnitude (measured on
  // PoCL: -0.006%, +0.0004%, -0.014%).
  CHECK(exact(0) == test::rel(2.9313e-5 * kTraction / 1e6, 1e-4));
  for (int k = 0; k < 3; ++k) {
    CAPTURE(k);
    CHECK(std::fabs(measured(k) - exact(k)) < kTolerance * std::fabs(exact(k)));
  }
  // The field is uniform: the fit leaves (almost) nothing.
  double worst = 0;
  for (size_t i = 0; i < n; ++i)
    worst = std::max({worst, std::fabs(gx(0) + gx(1) * X[i] + gx(2) * Y[i] - ux(i)),
                      std::fabs(gy(0) + gy(1) * X[i] + gy(2) * Y[i] - uy(i))});
  CHECK(worst < kTolerance * exact.cwiseAbs().maxCoeff() * 0.4);

  // Stresses: uniaxial in every element.
  for (const auto& [name, expected] : {std::pair{"SXX", kTraction}, std::pair{"SYY", 0.0}, std::pair{"SXY", 0.0}}) {
    CAPTURE(name);
    for (double v : test::last_element_values(exo, name)) CHECK(std::fabs(v - expected) < kTolerance * kTraction);
  }
}

}  // TEST_SUITE

TEST_SUITE("anisotropic") {

TEST_CASE("stable step modulus of a rotated orthotropic material: the fastest direction, whatever the angle") {
  // ρv² along the material 1 axis is c11 = 60 GPa, the largest over directions for these
  // constants; rotated by 30° the global C11 and C22 are only 45.5 and 25.5 GPa, so a
  // modulus read off them would overestimate the stable step by √(60/45.5) = 15%.
  for (double angle : {0.0, 30.0, 45.0, 90.0, 150.0}) {
    CAPTURE(angle);
    io::MaterialConfig m = test::material_config("slate", io::Elasticity::Hyperelastic, io::Plane::Strain);
    m.stiffness = io::Stiffness{kC11, kC22, kC12, kC66, 0.0, 0.0, angle};
    const MaterialConstants c = make_material(m, 0.1);
    CHECK(c.wave_modulus == doctest::Approx(kC11).epsilon(1e-6));
    if (angle == 30.0) CHECK(std::max(c.c[0], c.c[3]) == doctest::Approx(45.5e9).epsilon(1e-9));
  }
  // Isotropic hyperelastic: λ + 2μ.
  const auto iso = make_material(test::material_config("he", io::Elasticity::Hyperelastic, io::Plane::Strain), 0.1);
  CHECK(iso.wave_modulus == doctest::Approx(iso.lambda + 2 * iso.mu).epsilon(1e-12));
}

}  // TEST_SUITE
