// Shared test set-up: one OpenCL context for the whole test binary (the device is
// FDEM_DEVICE's, else auto: PoCL on CI, the GPU on the GPU machine), the one way the
// tests (and the validation driver) run a case on it, and small models built directly
// in C++.
#pragma once
#include <array>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/model/model.hpp"
#include "engine/run/run.hpp"

namespace fdem::test {

inline ClContext& context() {
  static ClContext cl("");
  return cl;
}

// Runs a prepared case on the shared context, as `fdem run` would; the progress lines
// go to `progress` (the validation driver's stdout), else nowhere. Throws what run_case
// throws (NumericalError, OutputError, InputError).
inline RunSummary run(const PreparedCase& prepared, const RunOptions& options = {}, std::ostream* progress = nullptr) {
  std::ostringstream dropped;
  return run_case(prepared, context(), progress ? *progress : dropped, false, options);
}

// Reads, meshes and runs a case file with `--set` overrides (KEY=VALUE, as on the
// command line).
inline RunSummary run(const std::string& case_path, const std::vector<std::string>& overrides = {},
                      const RunOptions& options = {}) {
  return run(prepare_case(case_path, overrides), options);
}

// Options that continue a run from `checkpoint` (fdem run --restart).
inline RunOptions restart_from(const std::string& checkpoint) {
  RunOptions options;
  options.restart = checkpoint;
  return options;
}

inline io::MaterialConfig material_config(const std::string& name, io::Elasticity elasticity, io::Plane plane,
                                          double viscosity = 0.0, bool anisotropic = false) {
  io::MaterialConfig m;
  m.name = name;
  m.regions = {name};
  m.density = 2500.0;
  m.young = 30e9;
  m.poisson = 0.22;
  m.elasticity = elasticity;
  m.plane = plane;
  m.viscosity = viscosity;
  if (anisotropic) m.stiffness = io::Stiffness{50e9, 20e9, 8e9, 12e9, 1e9, -2e9, 30.0};
  return m;
}

// The five constitutive variants the kernels support.
inline std::vector<io::MaterialConfig> all_material_variants(double viscosity = 0.0) {
  using E = io::Elasticity;
  using P = io::Plane;
  return {material_config("nh_strain", E::NeoHookean, P::Strain, viscosity),
          material_config("nh_stress", E::NeoHookean, P::Stress, viscosity),
          material_config("he_strain", E::Hyperelastic, P::Strain, viscosity),
          material_config("he_stress", E::Hyperelastic, P::Stress, viscosity),
          material_config("he_aniso", E::Hyperelastic, P::Strain, viscosity, true)};
}

// A model from explicit nodes and counter-clockwise triangles; material of triangle t
// is t % materials.size() (grouped into blocks as the model requires).
inline Model make_model(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<std::array<int, 3>>& triangles,
                        const std::vector<io::MaterialConfig>& materials, double thickness = 0.5) {
  Model m;
  m.thickness = thickness;
  m.x = x;
  m.y = y;
  for (size_t i = 0; i < x.size(); ++i) m.node_tags.push_back(static_cast<long>(i + 1));
  m.block_start.assign(materials.size() + 1, 0);
  for (size_t k = 0; k < materials.size(); ++k) {
    for (size_t t = 0; t < triangles.size(); ++t)
      if (t % materials.size() == k) {
        m.triangles.push_back(triangles[t]);
        m.triangle_material.push_back(static_cast<int>(k));
        m.triangle_tags.push_back(static_cast<long>(t + 1));
      }
    m.block_start[k + 1] = m.triangles.size();
    m.materials.push_back(make_material(materials[k], 0.1));
  }
  m.groups.push_back({});
  m.node_group.assign(x.size(), 0);
  m.vx0.assign(x.size(), 0.0);
  m.vy0.assign(x.size(), 0.0);
  return m;
}

// Random well-shaped counter-clockwise triangles, each with its own three nodes.
inline Model triangle_soup(size_t count, const std::vector<io::MaterialConfig>& materials, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x, y;
  std::vector<std::array<int, 3>> tris;
  for (size_t t = 0; t < count; ++t) {
    const double cx = u(rng), cy = u(rng), size = 0.05 + 0.05 * (u(rng) + 1);
    double px[3], py[3];
    for (int k = 0; k < 3; ++k) {
      const double angle = 2.0 * M_PI * k / 3.0 + 0.4 * u(rng);
      px[k] = cx + size * std::cos(angle) * (1 + 0.2 * u(rng));
      py[k] = cy + size * std::sin(angle) * (1 + 0.2 * u(rng));
    }
    const int base = static_cast<int>(x.size());
    for (int k = 0; k < 3; ++k) x.push_back(px[k]), y.push_back(py[k]);
    tris.push_back({base, base + 1, base + 2});
  }
  return make_model(x, y, tris, materials);
}

}  // namespace fdem::test
