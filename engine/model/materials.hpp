// Material constants as the kernels see them: one row of the material table
// (layout in cl_kernels/common.cl) per [[material]] of the case.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "engine/model/layouts.hpp"
#include "io/case_config.hpp"

namespace fdem {

// Voigt stiffness on (xx, yy, 2xy): c[0]=C11 c[1]=C12 c[2]=C16 c[3]=C22 c[4]=C26 c[5]=C66.
using Voigt = std::array<double, 6>;

struct MaterialConstants {
  std::string name;
  int model = 0;            // 0 Neo-Hookean, 1 hyperelastic
  double lambda = 0, mu = 0;  // Lamé constants of the 2D model [Pa]
  Voigt c{};                // global-frame Voigt stiffness [Pa] (Neo-Hookean: its small-strain limit)
  double viscosity = 0;     // η [Pa s]
  double density = 0;       // ρ [kg/m³]
  double wave_modulus = 0;  // P-wave modulus used for the stable time step [Pa]
};

// The 2D Lamé constants: plane strain λ = Eν/((1+ν)(1-2ν)); plane stress λ* = Eν/(1-ν²).
std::array<double, 2> lame_constants(double young, double poisson, io::Plane plane);

// Isotropic Voigt stiffness of the plane model.
Voigt isotropic_stiffness(double young, double poisson, io::Plane plane);

// Rotates a material-frame Voigt stiffness by `angle_deg` (counter-clockwise from the
// global x axis to the material 1 axis) into the global frame, through the 4th-order
// tensor: C'_ijkl = Q_ia Q_jb Q_kc Q_ld C_abcd.
Voigt rotate_stiffness(const Voigt& c, double angle_deg);

// The largest P-wave modulus ρ v² over all directions of propagation: the largest
// eigenvalue of the acoustic tensor C_ijkl n_j n_l over unit vectors n [Pa].
double largest_wave_modulus(const Voigt& c);

// `mean_edge` is the material's mean triangle edge length [m], the h of
// viscosity = "critical" (η = 2 h √(ρE)).
MaterialConstants make_material(const io::MaterialConfig& config, double mean_edge);

// The rows of the device's material table (layout::MATERIAL_STRIDE reals each, MAT_*).
std::vector<double> material_table(const std::vector<MaterialConstants>& materials);

}  // namespace fdem
