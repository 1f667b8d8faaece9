// Cohesive elements (CE4, Eqs. 4-14). One work-item per CE4: the opening o and slip s at
// three Gauss points of the edge, the cohesive tractions there (elastic, softening,
// unloading/reloading and compression branches), the irreversible damage state per point,
// the breaking test, and the four nodal forces written to the CE4's four slots
// (order i, j, j', i'; the node gather sums slots per node, no atomics).
//
// Integration: 3-point Gauss-Legendre on the edge, ξ = ½ ∓ √15/10 and ½ with weights
// 5/18, 8/18, 5/18 of the current length. This is the paper's Gauss rule, not Y-Geo's
// end-middle-end points with weights 1/6, 2/3, 1/6.
//
// Frame: face 1 = i→j (triangle 1, counter-clockwise, so its interior is on the left of
// i→j), face 2 = i'→j' (taken from the i side to the j side as well). δ(ξ) = x₂(ξ) - x₁(ξ);
// t ∥ (x_j - x_i) + (x_j' - x_i'); n = t turned clockwise (the right normal), pointing
// away from triangle 1's interior, so separation gives o = δ·n > 0; s = δ·t. The current
// length is that of the mid-surface, |(x_j - x_i) + (x_j' - x_i')| / 2.
//
// Law per Gauss point (all from the per-CE4 parameter row, see COH_* below):
//   damage, Eq. 9: D = min(1, √(⟨o-o_p⟩²/o_t² + ⟨|s|-s_p⟩²/s_t²)) (⟨x⟩ = max(x, 0)); the
//     branch is mode I (only o > o_p), mode II (only |s| > s_p) or mixed (both);
//   irreversibility: per point D_max, o_max, max |s| are kept; f = f(D_max) (Eq. 10,
//     decreasing, so f never recovers);
//   normal, Eqs. 4 and 13: o < 0: 2 o T_s / o_overlap (no f(D));
//     o_max > o_p and o < o_max: f T_s o / o_max (unloading/reloading);
//     o <= o_p: (2o/o_p - (o/o_p)²) f T_s;  else f T_s;
//   shear, Eqs. 5 and 14, strength S = max(0, -σ tanφ + f c) (Mohr-Coulomb; only the
//     cohesion is softened; the max(0, .) keeps a strongly tensile σ from reversing τ):
//     s_max > s_p and |s| < s_max: S |s| / s_max;  |s| <= s_p: (2|s|/s_p - (|s|/s_p)²) S;
//     else S;  τ takes the sign of s.
// Breaking: when D_max = 1 at two or more of the three points the CE4 breaks for good and
// carries no force from that step on. Mode: each point records the branch (1 I, 2 II,
// 3 mixed) of the step at which its D reached 1; the CE4's mode is that branch if all
// points at D = 1 agree, else 3 (mixed). The time passed to the step is recorded.
// Forces: p = (σ n + τ t) w L thickness at each point; face 1 gets +p, face 2 gets -p
// (the traction pulls the faces together when open, pushes them apart when overlapping,
// and opposes the slip), distributed with the linear shape functions (1-ξ, ξ).

#define COH_STRIDE 12
#define COH_OP 0       /* o_p = 2 h T_s / P_f [m] (Eq. 6) */
#define COH_SP 1       /* s_p = 2 h c / P_tan [m] (Eq. 7) */
#define COH_OOV 2      /* o_overlap = 2 h T_s / P_overlap [m] (Eq. 8) */
#define COH_OT 3       /* o_t = G_fI / (T_s I_f) [m] */
#define COH_ST 4       /* s_t = G_fII / (c I_f) [m] */
#define COH_TS 5       /* tensile strength T_s [Pa] */
#define COH_C 6        /* cohesion c [Pa] */
#define COH_TANPHI 7   /* tan φ */
#define COH_A 8        /* softening shape A, B, C (Eq. 10) */
#define COH_B 9
#define COH_CEXP 10
#define COH_H 11       /* initial edge length h [m] (set-up only; kept for output/debug) */

// f(D) of Eq. 10.
inline real coh_softening(real D, real A, real B, real C) {
  const real ab = A + B;
  const real decay = (real)1 - (ab - (real)1) / ab * exp(D * (A + C * B) / (ab * ((real)1 - ab)));
  return decay * (A * ((real)1 - D) + B * pow((real)1 - D, C));
}

// One work-item per CE4: kinematics, law and nodal forces of CE4 `e`; updates its three
// Gauss-point states, its status (broken, mode) and its output row.
// gp_state: real4 per Gauss point (D_max, o_max [m], max|s| [m], branch that brought D to 1).
// status: int2 per CE4 (broken 0/1, mode 0/1/2/3). output: real4 per CE4 (max D over the
// points, mean opening [m], mean slip [m], time it broke [s]).
__kernel void cohesive_forces(const uint n_ce4,
                              __global const uint4* restrict ce4_nodes,
                              __global const real* restrict params,
                              __global const real2* restrict position,
                              const real thickness,
                              const real time,
                              __global real4* restrict gp_state,
                              __global int2* restrict status,
                              __global real4* restrict output,
                              __global real2* restrict slots) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  const uint4 nd = ce4_nodes[e];  // (i, j, j', i')
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  // End gaps first: differences of nearly equal coordinates are exact, so δ keeps its
  // relative precision however far the CE4 is from the origin.
  const real2 gap_i = xi2 - xi, gap_j = xj2 - xj;
  const real2 chord = (xj - xi) + (xj2 - xi2);
  const real chord_length = length(chord);
  const real2 t = chord / chord_length;
  const real2 n = (real2)(t.y, -t.x);
  const real scale = (real)0.5 * chord_length * thickness;  // L t

  const real r = (real)0.3872983346207417;  // √15 / 10
  const real gauss_xi[3] = {(real)0.5 - r, (real)0.5, (real)0.5 + r};
  const real gauss_w[3] = {(real)5 / (real)18, (real)8 / (real)18, (real)5 / (real)18};

  real o[3], s[3];
  real mean_o = 0, mean_s = 0;
  for (int g = 0; g < 3; ++g) {
    const real2 delta = ((real)1 - gauss_xi[g]) * gap_i + gauss_xi[g] * gap_j;
    o[g] = dot(delta, n);
    s[g] = dot(delta, t);
    mean_o += gauss_w[g] * o[g];
    mean_s += gauss_w[g] * s[g];
  }

  int2 st = status[e];
  real broken_time = output[e].w;
  real damage = 0;
  real2 f_i = (real2)(0, 0), f_j = (real2)(0, 0);

  if (!st.x) {
    __global const real* p = params + COH_STRIDE * e;
    const real op = p[COH_OP], sp = p[COH_SP], oov = p[COH_OOV], ot = p[COH_OT], stl = p[COH_ST];
    const real Ts = p[COH_TS], coh = p[COH_C], tanphi = p[COH_TANPHI];
    const real A = p[COH_A], B = p[COH_B], C = p[COH_CEXP];
    int at_one = 0, first_branch = 0, same_branch = 1;

    for (int g = 0; g < 3; ++g) {
      real4 gs = gp_state[3 * e + g];
      const real og = o[g], sa = fabs(s[g]);
      const real over_o = fmax(og - op, (real)0), over_s = fmax(sa - sp, (real)0);
      real D = 0;
      int branch = 0;
      if (over_o > (real)0 || over_s > (real)0) {
        const real a = over_o / ot, b = over_s / stl;
        D = fmin((real)1, sqrt(a * a + b * b));
        branch = over_o > (real)0 ? (over_s > (real)0 ? 3 : 1) : 2;
      }
      if (D >= (real)1 && gs.x < (real)1) gs.w = (real)branch;
      gs.x = fmax(gs.x, D);
      gs.y = fmax(gs.y, og);
      gs.z = fmax(gs.z, sa);
      gp_state[3 * e + g] = gs;
      damage = fmax(damage, gs.x);
      if (gs.x >= (real)1) {
        const int b = (int)gs.w;
        if (at_one == 0) first_branch = b;
        else if (b != first_branch) same_branch = 0;
        ++at_one;
      }

      const real f = coh_softening(gs.x, A, B, C);
      real sigma;
      if (og < (real)0) {
        sigma = (real)2 * og * Ts / oov;
      } else if (gs.y > op && og < gs.y) {
        sigma = f * Ts * og / gs.y;
      } else if (og <= op) {
        const real q = og / op;
        sigma = ((real)2 * q - q * q) * f * Ts;
      } else {
        sigma = f * Ts;
      }

      const real strength = fmax((real)0, -sigma * tanphi + f * coh);
      real tau;
      if (gs.z > sp && sa < gs.z) {
        tau = strength * sa / gs.z;
      } else if (sa <= sp) {
        const real q = sa / sp;
        tau = ((real)2 * q - q * q) * strength;
      } else {
        tau = strength;
      }
      if (s[g] < (real)0) tau = -tau;

      const real2 pg = (sigma * n + tau * t) * (gauss_w[g] * scale);
      f_i += ((real)1 - gauss_xi[g]) * pg;
      f_j += gauss_xi[g] * pg;
    }

    if (at_one >= 2) {
      st = (int2)(1, same_branch ? first_branch : 3);
      status[e] = st;
      broken_time = time;
    }
  } else {
    for (int g = 0; g < 3; ++g) damage = fmax(damage, gp_state[3 * e + g].x);
  }

  if (st.x) f_i = f_j = (real2)(0, 0);
  slots[4 * e] = f_i;
  slots[4 * e + 1] = f_j;
  slots[4 * e + 2] = -f_j;
  slots[4 * e + 3] = -f_i;
  output[e] = (real4)(damage, mean_o, mean_s, broken_time);
}
