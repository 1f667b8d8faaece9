#include "engine/model/materials.hpp"

#include <algorithm>
#include <cmath>

namespace fdem {

std::array<double, 2> lame_constants(double E, double nu, io::Plane plane) {
  const double mu = E / (2.0 * (1.0 + nu));
  const double lambda = plane == io::Plane::Strain ? E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
                                                   : E * nu / (1.0 - nu * nu);
  return {lambda, mu};
}

Voigt isotropic_stiffness(double E, double nu, io::Plane plane) {
  const auto [lambda, mu] = lame_constants(E, nu, plane);
  return {lambda + 2 * mu, lambda, 0.0, lambda + 2 * mu, 0.0, mu};
}

Voigt rotate_stiffness(const Voigt& v, double angle_deg) {
  // Voigt index of the tensor pair (i, j): 0 xx, 1 yy, 2 xy
  auto voigt = [](int i, int j) { return i == j ? i : 2; };
  const double C3[3][3] = {{v[0], v[1], v[2]}, {v[1], v[3], v[4]}, {v[2], v[4], v[5]}};
  double C[2][2][2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l) C[i][j][k][l] = C3[voigt(i, j)][voigt(k, l)];
  const double a = angle_deg * M_PI / 180.0;
  const double Q[2][2] = {{std::cos(a), -std::sin(a)}, {std::sin(a), std::cos(a)}};
  double R[2][2][2][2] = {};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l)
          for (int p = 0; p < 2; ++p)
            for (int q = 0; q < 2; ++q)
              for (int r = 0; r < 2; ++r)
                for (int s = 0; s < 2; ++s)
                  R[i][j][k][l] += Q[i][p] * Q[j][q] * Q[k][r] * Q[l][s] * C[p][q][r][s];
  return {R[0][0][0][0], R[0][0][1][1], R[0][0][0][1], R[1][1][1][1], R[1][1][0][1], R[0][1][0][1]};
}

double largest_wave_modulus(const Voigt& c) {
  // Acoustic tensor A_ik = C_ijkl n_j n_l for n = (cos θ, sin θ); ρ v² are its eigenvalues.
  // Its entries are quadratic in (cos θ, sin θ), so θ in [0, π) covers every direction;
  // 3600 samples find the maximum to about 1e-6 relative.
  double largest = 0;
  for (int k = 0; k < 3600; ++k) {
    const double t = M_PI * k / 3600.0, n1 = std::cos(t), n2 = std::sin(t);
    const double a11 = c[0] * n1 * n1 + 2 * c[2] * n1 * n2 + c[5] * n2 * n2;
    const double a22 = c[5] * n1 * n1 + 2 * c[4] * n1 * n2 + c[3] * n2 * n2;
    const double a12 = c[2] * n1 * n1 + (c[1] + c[5]) * n1 * n2 + c[4] * n2 * n2;
    largest = std::max(largest, 0.5 * (a11 + a22) + std::hypot(0.5 * (a11 - a22), a12));
  }
  return largest;
}

MaterialConstants make_material(const io::MaterialConfig& config, double mean_edge) {
  MaterialConstants m;
  m.name = config.name;
  m.model = config.elasticity == io::Elasticity::NeoHookean ? 0 : 1;
  const auto lame = lame_constants(config.young, config.poisson, config.plane);
  m.lambda = lame[0];
  m.mu = lame[1];
  if (config.stiffness) {
    const auto& s = *config.stiffness;
    m.c = rotate_stiffness({s.c11, s.c12, s.c16, s.c22, s.c26, s.c66}, s.angle);
  } else {
    m.c = isotropic_stiffness(config.young, config.poisson, config.plane);
  }
  m.density = config.density;
  m.viscosity = config.viscosity_critical
                    ? 2.0 * mean_edge * std::sqrt(config.density * config.young)
                    : config.viscosity;
  // The fastest P-wave of a rotated anisotropic material need not run along x or y (at
  // 30° the material 1 axis is stiffer than C11 and C22 of the global frame), so the
  // stable step uses the largest modulus over all directions.
  m.wave_modulus = m.model == 0 ? m.lambda + 2 * m.mu : largest_wave_modulus(m.c);
  return m;
}

std::vector<double> material_table(const std::vector<MaterialConstants>& materials) {
  std::vector<double> table;
  for (const auto& m : materials) {
    double row[layout::MATERIAL_STRIDE] = {};
    row[layout::MAT_MODEL] = m.model;
    row[layout::MAT_LAMBDA] = m.lambda;
    row[layout::MAT_MU] = m.mu;
    const int voigt[6] = {layout::MAT_C11, layout::MAT_C12, layout::MAT_C16,
                          layout::MAT_C22, layout::MAT_C26, layout::MAT_C66};
    for (int k = 0; k < 6; ++k) row[voigt[k]] = m.c[k];
    row[layout::MAT_VISCOSITY] = m.viscosity;
    row[layout::MAT_DENSITY] = m.density;
    table.insert(table.end(), row, row + layout::MATERIAL_STRIDE);
  }
  return table;
}

}  // namespace fdem
