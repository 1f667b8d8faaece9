// Shared rig of the cohesive (CE4) tests: CE4s with their own four nodes whose positions a
// test prescribes, the stage under test, the reference laws, and helpers to place gaps,
// read tractions and integrate work (tests/test_cohesive*.cpp).
#pragma once
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/device/device_arrays.hpp"
#include "engine/stages/cohesive_forces.hpp"
#include "fixture.hpp"
#include "reference_cohesive.hpp"

namespace fdem::cohesive_rig {

namespace rc = fdem::reference_cohesive;
using rc::Vec;

constexpr double kRel = kDoublePrecision ? 1e-12 : 2e-4;
// Float positions of a CE4 0.1-1 m from the origin are resolved to ~1e-8 m, which is not
// small next to gaps of 1e-5 m: gap-level checks are loosened accordingly there.
constexpr double kGapTol = kDoublePrecision ? 1e-12 : 1e-3;

inline FractureProperties rock() {
  FractureProperties p;
  p.tensile_strength = 5e6;
  p.cohesion = 12e6;
  p.friction_angle = 30.0;
  p.gf1 = 40.0;
  p.gf2 = 200.0;
  p.penalty_opening = 2e13;
  p.penalty_sliding = 2e13;
  p.penalty_overlap = 2e13;
  return p;
}

// CE4s each with their own four nodes (i, j, j', i' = 4e .. 4e+3), positions driven directly.
struct Rig {
  ClContext& cl = test::context();
  CohesiveModel model;
  std::vector<real2> ref;
  compute::buffer position, velocity, ref_position;
  std::unique_ptr<CohesiveForces> stage;
  // Steps taken (the stage records the step a CE4 is released). The first is step 1: the
  // stage books no displacement in step 0, where a run's nodes are at their reference
  // positions, and a test may place them elsewhere before its first step.
  long steps = 1;
  std::vector<real2> x_before;  // the positions of the last step (at first the reference)
  std::vector<rc::Law> laws;

  // One CE4 per (reference i, reference j, properties).
  Rig(const std::vector<std::pair<Vec, Vec>>& edges, const std::vector<FractureProperties>& props, double thickness) {
    model.thickness = thickness;
    model.fracture = props;
    model.dt = 1.0;  // the rig's velocities are the displacements per step
    for (size_t e = 0; e < edges.size(); ++e) {
      const int b = static_cast<int>(4 * e);
      model.ce4.push_back({b, b + 1, b + 2, b + 3});
      model.properties.push_back(static_cast<int>(e % props.size()));
      const Vec& a = edges[e].first;
      const Vec& c = edges[e].second;
      for (const Vec& p : {a, c, c, a}) ref.push_back({real(p.x()), real(p.y())});
      // h from the same stored (possibly float) coordinates the stage reads
      const double h = std::hypot(double(ref[b + 1].x) - double(ref[b].x), double(ref[b + 1].y) - double(ref[b].y));
      laws.push_back(rc::make_law(props[e % props.size()], h));
    }
    position = cl.allocate(ref.size() * sizeof(real2), "test_position");
    velocity = cl.allocate(ref.size() * sizeof(real2), "test_velocity");
    ref_position = cl.allocate(ref.size() * sizeof(real2), "test_ref_position");
    upload(cl, position, ref);
    upload(cl, velocity, std::vector<real2>(ref.size(), real2{0, 0}));
    upload(cl, ref_position, ref);
    x_before = ref;
    stage = std::make_unique<CohesiveForces>(cl, model, position, velocity, ref_position);
  }

  // Sets the positions (stored as real) and the velocities that moved the nodes there
  // from the last step's (dt = 1), runs one step and returns the slot forces.
  std::vector<real2> step(std::vector<real2>& x, double time) {
    std::vector<real2> v(x.size());
    for (size_t k = 0; k < x.size(); ++k) v[k] = real2{x[k].x - x_before[k].x, x[k].y - x_before[k].y};
    upload(cl, position, x);
    upload(cl, velocity, v);
    x_before = x;
    stage->enqueue(time, steps++);
    return download<real2>(cl, stage->slots(), 4 * stage->size());
  }
};

inline std::array<Vec, 4> nodes_of(const std::vector<real2>& x, size_t e) {
  std::array<Vec, 4> out;
  for (int k = 0; k < 4; ++k) out[k] = Vec(x[4 * e + k].x, x[4 * e + k].y);
  return out;
}

inline Vec vec(real2 v) { return Vec(v.x, v.y); }

inline std::string fixed(double v, int digits = 6) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

// Unit tangent and the right normal (away from triangle 1) of a reference edge a→b.
inline std::pair<Vec, Vec> frame(const Vec& a, const Vec& b) {
  const Vec t = (b - a).normalized();
  return {t, Vec(t.y(), -t.x())};
}

// One CE4 i, j, j', i' with the gaps gap_i (at i) and gap_j (at j) given as (normal, tangential)
// components in the frame of the reference edge; face 1 moves by -½ gap, face 2 by +½ gap.
inline void place(std::vector<real2>& x, size_t e, const Vec& a, const Vec& b, const Vec& gap_i, const Vec& gap_j) {
  const auto [t, n] = frame(a, b);
  const Vec gi = gap_i.x() * n + gap_i.y() * t, gj = gap_j.x() * n + gap_j.y() * t;
  const Vec p[4] = {a - 0.5 * gi, b - 0.5 * gj, b + 0.5 * gj, a + 0.5 * gi};
  for (int k = 0; k < 4; ++k) x[4 * e + k] = {real(p[k].x()), real(p[k].y())};
}

// Normal and tangential traction on face 1 (σ, τ) from the summed face-2 force of CE4 e.
inline std::pair<double, double> face_traction(const std::vector<real2>& f, const std::vector<real2>& x, size_t e,
                                        double thickness) {
  const auto p = nodes_of(x, e);
  const Vec sum = (p[1] - p[0]) + (p[2] - p[3]);
  const Vec t = sum.normalized(), n(t.y(), -t.x());
  const double area = 0.5 * sum.norm() * thickness;
  const Vec face2 = vec(f[4 * e + 2]) + vec(f[4 * e + 3]);
  return {-face2.dot(n) / area, -face2.dot(t) / area};
}

// Work done on the CE4 by the agent that moves its nodes: -∫ F_coh · dx, trapezoid rule.
inline double work_increment(const std::vector<real2>& f0, const std::vector<real2>& f1, const std::vector<real2>& x0,
                      const std::vector<real2>& x1) {
  double w = 0;
  for (size_t a = 0; a < f0.size(); ++a)
    w -= 0.5 * (vec(f0[a]) + vec(f1[a])).dot(vec(x1[a]) - vec(x0[a]));
  return w;
}

// ∫₀^D f, composite Simpson on 400 panels (independent of softening_integral's adaptive rule).
inline double softening_area(double D, const FractureProperties& p) {
  const int panels = 400;
  const double h = D / panels;
  double sum = softening(0.0, p.a, p.b, p.c) + softening(D, p.a, p.b, p.c);
  for (int k = 1; k < panels; ++k) sum += (k % 2 ? 4.0 : 2.0) * softening(k * h, p.a, p.b, p.c);
  return sum * h / 3.0;
}

// Energy one point has dissipated per unit area on the monotonic envelope at gap x beyond
// the elastic limit x_p (peak traction T, critical gap x_t): the work
// ∫₀^x_p parabola + ∫ f T dx minus the secant energy ½ f T x it would give back.
inline double envelope_dissipated(double x, double xp, double xt, double T, const FractureProperties& p) {
  if (x <= xp) return 0.0;
  const double D = std::min(1.0, (x - xp) / xt);
  return 2.0 / 3.0 * T * xp + T * xt * softening_area(D, p) - 0.5 * softening(D, p.a, p.b, p.c) * T * x;
}

}  // namespace fdem::cohesive_rig
