// Plain C++ reference of the CE4 law (Eqs. 4-14 with the conventions of
// docs/physics-notes.md), written from the equations and independently of
// cl_kernels/cohesive_forces.cl. Double precision, Eigen vectors.
#pragma once
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "engine/model/cohesive_model.hpp"

namespace fdem::reference_cohesive {

using Vec = Eigen::Vector2d;

// Constants of one CE4, from its fracture properties and initial edge length h.
struct Law {
  double h;  // initial edge length: tractions act per unit reference area h t
  double o_p, s_p, o_overlap, o_t, s_t;
  double tensile, cohesion, tan_phi;
  double A, B, C;
};

inline Law make_law(const FractureProperties& p, double h) {
  const double I_f = softening_integral(p.a, p.b, p.c);
  Law law;
  law.h = h;
  law.o_p = 2.0 * h * p.tensile_strength / p.penalty_opening;        // Eq. 6
  law.s_p = 2.0 * h * p.cohesion / p.penalty_sliding;                // Eq. 7
  law.o_overlap = 2.0 * h * p.tensile_strength / p.penalty_overlap;  // Eq. 8
  law.o_t = p.gf1 / (I_f * p.tensile_strength);                      // Eq. 11 with σ = f T_s
  law.s_t = p.gf2 / (I_f * p.cohesion);                              // Eq. 12 at σ = 0
  law.tensile = p.tensile_strength;
  law.cohesion = p.cohesion;
  law.tan_phi = std::tan(p.friction_angle * M_PI / 180.0);
  law.A = p.a;
  law.B = p.b;
  law.C = p.c;
  return law;
}

// Eq. 10.
inline double f_of(double D, const Law& law) {
  const double sum = law.A + law.B;
  const double rate = (law.A + law.C * law.B) / (sum * (1.0 - sum));
  const double first = 1.0 - std::exp(rate * D) * (sum - 1.0) / sum;
  const double second = law.A * (1.0 - D) + law.B * std::pow(1.0 - D, law.C);
  return first * second;
}

enum Branch { kNone = 0, kModeI = 1, kModeII = 2, kMixed = 3 };

struct PointState {
  double D_max = 0, o_max = 0, s_max = 0;
  int branch_at_break = kNone;   // Eq. 9's branch (by o > o_p, |s| > s_p) when D reached 1
  double opening_share = 0;      // a² / (a² + b²) of Eq. 9 when D reached 1
  double slip_f = 0;             // slip of the friction element (stick spring + Coulomb cap)
};

struct Ce4State {
  std::array<PointState, 3> point;
  bool broken = false;    // closed (still pressing and rubbing) or released
  bool released = false;  // let go for good: no force from then on
  int mode = kNone;
  double time = -1.0;
  double work = 0;        // work done on the CE4 so far [J]
  double dissipated = 0;  // fracture dissipation: max over time of (work - held) [J]
  double held = 0;        // elastic energy it holds now [J]
  std::array<Vec, 4> x_before{Vec::Zero(), Vec::Zero(), Vec::Zero(), Vec::Zero()};  // positions and forces
  std::array<Vec, 4> force_before{Vec::Zero(), Vec::Zero(), Vec::Zero(), Vec::Zero()};  // of the last step
  bool started = false;
};

// Failure mode of a CE4 from the mean opening share of its points at D = 1: the term of
// Eq. 9 that supplies at least 90 % of D² names the mode, otherwise mixed.
inline int mode_of_share(double share) { return share >= 0.9 ? kModeI : share <= 0.1 ? kModeII : kMixed; }

// What the branches did at one point (tests use it for coverage and bounds).
struct PointResult {
  double o = 0, s = 0, sigma = 0, tau = 0, weight = 0;
  double tau_c = 0, tau_f = 0;  // cohesive and friction parts of tau
  bool compressed = false, normal_unloading = false, shear_unloading = false, softening = false;
  Vec delta = Vec::Zero();
};

struct Result {
  std::array<Vec, 4> force;  // i, j, j', i'
  double damage = 0, opening = 0, slip = 0;
  std::array<PointResult, 3> point;
};

// Trial damage of Eq. 9, the branch that produced it and the opening share x² / (x² + y²).
struct Trial {
  double D;
  int branch;
  double share;
};
inline Trial trial_damage(const Law& law, double o, double s) {
  const bool tensile = o > law.o_p, sheared = std::fabs(s) > law.s_p;
  if (!tensile && !sheared) return {0.0, kNone, 0.0};
  const double x = tensile ? (o - law.o_p) / law.o_t : 0.0;
  const double y = sheared ? (std::fabs(s) - law.s_p) / law.s_t : 0.0;
  const int branch = tensile && sheared ? kMixed : tensile ? kModeI : kModeII;
  return {std::min(1.0, std::hypot(x, y)), branch, x * x / (x * x + y * y)};
}

// Elastic energy per unit area a point holds (what unloading to o = s = 0 along its
// current branches, state frozen, gives back). Eq. 4's parabola integrates to
// peak (x²/x_p - x³/(3 x_p²)); the secants of Eqs. 13-14 hold half traction × opening;
// the friction element holds τ_f² / (2 k_f).
inline double held_energy(const Law& law, const PointState& st, double o, double s, double sigma, double tau_c,
                          double tau_f) {
  const double f = f_of(st.D_max, law);
  double normal;
  if (o < 0) {
    normal = 0.5 * (2.0 * law.tensile / law.o_overlap) * o * o;
  } else if (st.o_max > law.o_p) {
    normal = 0.5 * sigma * o;
  } else {
    normal = law.tensile * f * (o * o / law.o_p - o * o * o / (3.0 * law.o_p * law.o_p));
  }
  const double a = std::fabs(s);
  double shear;
  if (st.s_max > law.s_p) {
    shear = 0.5 * std::fabs(tau_c) * a;
  } else {
    shear = law.cohesion * f * (a * a / law.s_p - a * a * a / (3.0 * law.s_p * law.s_p));
  }
  const double k_f = 2.0 * law.cohesion / law.s_p;
  return normal + shear + 0.5 * tau_f * tau_f / k_f;
}

// The friction element at one point: a stick spring k_f = P_tan / h on s - s_f, capped at
// tanφ max(0, -σ); past the cap the slip s_f moves. Returns τ_f; updates s_f.
inline double friction_element(const Law& law, PointState& st, double s, double sigma) {
  const double k_f = 2.0 * law.cohesion / law.s_p;
  const double cap = law.tan_phi * std::max(0.0, -sigma);
  double tf = k_f * (s - st.slip_f);
  if (std::fabs(tf) > cap) {
    tf = tf > 0 ? cap : -cap;
    st.slip_f = s - tf / k_f;
  }
  return tf;
}

// Tractions at one point given its (already updated) damage state; updates the friction
// element's slip. Shear = cohesive part (Eqs. 5 and 14 with strength f c) + friction part
// (stick spring k_f = P_tan / h on s - s_f, capped at tanφ max(0, -σ)).
inline void tractions(const Law& law, PointState& st, double o, double s, PointResult& r) {
  const double f = f_of(st.D_max, law);
  r.softening = st.D_max > 0;
  if (o < 0) {
    r.compressed = true;
    r.sigma = o / law.o_overlap * 2.0 * law.tensile;
  } else if (st.o_max > law.o_p && o < st.o_max) {
    r.normal_unloading = true;
    r.sigma = law.tensile * f * (o / st.o_max);  // Eq. 13
  } else if (o > law.o_p) {
    r.sigma = law.tensile * f;
  } else {
    const double q = o / law.o_p;
    r.sigma = law.tensile * f * q * (2.0 - q);
  }
  const double strength = law.cohesion * f;
  const double a = std::fabs(s);
  double magnitude;
  if (st.s_max > law.s_p && a < st.s_max) {
    r.shear_unloading = true;
    magnitude = strength * (a / st.s_max);  // Eq. 14
  } else if (a > law.s_p) {
    magnitude = strength;
  } else {
    const double q = a / law.s_p;
    magnitude = strength * q * (2.0 - q);
  }
  r.tau_c = s < 0 ? -magnitude : magnitude;
  r.tau_f = friction_element(law, st, s, r.sigma);
  r.tau = r.tau_c + r.tau_f;
}

// A broken CE4 that is still closed: no strength (no tension, no cohesion), the
// compression branch and the friction element as before (state frozen).
inline void closed_tractions(const Law& law, PointState& st, double o, double s, PointResult& r) {
  r.compressed = o < 0;
  r.normal_unloading = r.shear_unloading = r.softening = false;
  r.sigma = o < 0 ? o / law.o_overlap * 2.0 * law.tensile : 0.0;
  r.tau_c = 0;
  r.tau_f = friction_element(law, st, s, r.sigma);
  r.tau = r.tau_f;
}

// What a closed CE4's point holds: the compression branch and the friction element.
inline double closed_held_energy(const Law& law, double o, double tau_f) {
  const double k_f = 2.0 * law.cohesion / law.s_p;
  return (o < 0 ? law.tensile / law.o_overlap * o * o : 0.0) + 0.5 * tau_f * tau_f / k_f;
}

// One step of one CE4 at nodal positions x (order i, j, j', i').
inline Result step(const Law& law, Ce4State& state, const std::array<Vec, 4>& x, double thickness, double time) {
  static const double root = std::sqrt(15.0) / 10.0;
  static const std::array<double, 3> xi{0.5 - root, 0.5, 0.5 + root};
  static const std::array<double, 3> weight{5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};

  const Vec face1 = x[1] - x[0], face2 = x[2] - x[3];  // both from the i side to the j side
  const Vec sum = face1 + face2;
  const Vec t = sum.normalized();
  const Vec n(t.y(), -t.x());  // right of t: away from triangle 1 (counter-clockwise, interior left)
  const Vec gap_i = x[3] - x[0], gap_j = x[2] - x[1];

  Result res;
  for (auto& f : res.force) f.setZero();
  int at_one = 0;
  std::array<double, 3> share_of{};
  for (int g = 0; g < 3; ++g) {
    PointResult& p = res.point[g];
    p.delta = (1.0 - xi[g]) * gap_i + xi[g] * gap_j;
    p.o = p.delta.dot(n);
    p.s = p.delta.dot(t);
    p.weight = weight[g];
    res.opening += weight[g] * p.o;
    res.slip += weight[g] * p.s;
    PointState& st = state.point[g];
    if (state.broken && !state.released) closed_tractions(law, st, p.o, p.s, p);
    if (!state.broken) {
      const Trial trial = trial_damage(law, p.o, p.s);
      const double D = trial.D;
      if (D >= 1.0 && st.D_max < 1.0) st.branch_at_break = trial.branch, st.opening_share = trial.share;
      st.D_max = std::max(st.D_max, D);
      st.o_max = std::max(st.o_max, p.o);
      st.s_max = std::max(st.s_max, std::fabs(p.s));
      tractions(law, st, p.o, p.s, p);
      if (st.D_max >= 1.0) share_of[at_one++] = st.opening_share;
    }
    res.damage = std::max(res.damage, st.D_max);
  }
  if (state.released) return res;
  const bool breaks = !state.broken && at_one >= 2;
  if (breaks) {
    state.broken = true;
    state.time = time;
    double mean = 0;
    for (int k = 0; k < at_one; ++k) mean += share_of[k] / at_one;
    state.mode = mode_of_share(mean);
    for (int g = 0; g < 3; ++g) closed_tractions(law, state.point[g], res.point[g].o, res.point[g].s, res.point[g]);
  }
  // A closed CE4 lets go when every point has opened or one has slid past h / 2.
  bool opened = true;
  double slid = 0;
  for (const PointResult& p : res.point) {
    opened = opened && p.o >= 0;
    slid = std::max(slid, std::fabs(p.s));
  }
  const bool releases = state.broken && (opened || slid > 0.5 * law.h);
  if (releases) state.released = true;
  // Forces (none once released): the gradient of the potential
  // h t Σ_g w_g ψ_g(o_g, s_g) with the state frozen: the traction pairs at the points
  // plus the frame's term ±(M / |c|) n (M = h t Σ w (τ o - σ s)), which cancels the
  // traction pairs' moment.
  double held = 0, moment = 0;
  const double area = law.h * thickness;
  for (int g = 0; g < 3; ++g) {
    PointResult& p = res.point[g];
    PointState& st = state.point[g];
    const Vec traction = p.sigma * n + p.tau * t;  // on face 1, towards face 2 when open
    Vec push = Vec::Zero();
    if (!releases) {
      push = traction * (p.weight * area);
      held += p.weight * area *
              (state.broken ? closed_held_energy(law, p.o, p.tau_f)
                            : held_energy(law, st, p.o, p.s, p.sigma, p.tau_c, p.tau_f));
      moment += p.weight * area * (p.tau * p.o - p.sigma * p.s);
    }
    const double N_i = 1.0 - xi[g], N_j = xi[g];
    res.force[0] += N_i * push;
    res.force[1] += N_j * push;
    res.force[2] -= N_j * push;
    res.force[3] -= N_i * push;
  }
  if (!releases) {
    const Vec m = moment / sum.norm() * n;
    res.force[0] += m;
    res.force[1] -= m;
    res.force[2] -= m;
    res.force[3] += m;
  }
  // Work done on the CE4 by whatever moves its nodes: -Σ_a ½ (F_a,before + F_a) · Δx_a.
  if (state.started)
    for (int a = 0; a < 4; ++a) state.work -= 0.5 * (state.force_before[a] + res.force[a]).dot(x[a] - state.x_before[a]);
  state.started = true;
  state.x_before = x;
  state.force_before = res.force;
  state.held = held;
  state.dissipated = std::max(state.dissipated, state.work - held);
  return res;
}

}  // namespace fdem::reference_cohesive
