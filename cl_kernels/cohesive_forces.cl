// Cohesive elements (CE4, Eqs. 4-14). One work-item per CE4: the opening o and slip s at
// three Gauss points of the edge, the cohesive tractions there (elastic, softening,
// unloading/reloading and compression branches), the irreversible damage state per point,
// the breaking test, the four nodal forces written to the CE4's four slots (order i, j,
// j', i'; the node gather sums slots per node, no atomics) and the CE4's energy account.
//
// Integration: 3-point Gauss-Legendre on the edge, ξ = ½ ∓ √15/10 and ½ with weights
// 5/18, 8/18, 5/18 of the initial length h (see Forces). This is the paper's Gauss rule,
// not Y-Geo's end-middle-end points with weights 1/6, 2/3, 1/6.
//
// Frame: face 1 = i→j (triangle 1, counter-clockwise, so its interior is on the left of
// i→j), face 2 = i'→j' (taken from the i side to the j side as well). δ(ξ) = x₂(ξ) - x₁(ξ);
// t ∥ (x_j - x_i) + (x_j' - x_i'); n = t turned clockwise (the right normal), pointing
// away from triangle 1's interior, so separation gives o = δ·n > 0; s = δ·t. The chord
// c = (x_j - x_i) + (x_j' - x_i') is twice the mid-surface; |c| enters the frame's force.
//
// Law per Gauss point (all from the per-CE4 parameter row, see COH_* below):
//   damage, Eq. 9: D = min(1, √(a² + b²)) with a = ⟨o-o_p⟩/o_t, b = ⟨|s|-s_p⟩/s_t
//     (⟨x⟩ = max(x, 0));
//   irreversibility: per point D_max, o_max, max |s| are kept; f = f(D_max) (Eq. 10,
//     decreasing, so f never recovers);
//   normal, Eqs. 4 and 13: o < 0: 2 o T_s / o_overlap (no f(D));
//     o_max > o_p and o < o_max: f T_s o / o_max (unloading/reloading);
//     o <= o_p: (2o/o_p - (o/o_p)²) f T_s;  else f T_s;
//   shear = cohesive part + friction part:
//     cohesive, Eqs. 5 and 14 with the strength f c: s_max > s_p and |s| < s_max:
//       f c |s| / s_max;  |s| <= s_p: (2|s|/s_p - (|s|/s_p)²) f c;  else f c; sign of s;
//     friction (the -σ tanφ of Eq. 5 under compression): a stick spring of stiffness
//       k_f = 2c/s_p = P_tan/h on s - s_f, capped at tanφ max(0, -σ); past the cap the
//       slip s_f of the element moves (Coulomb), so the cap is reached again after a
//       reversal only by slipping back. Not softened by f(D).
// Where this departs from Eq. 5 and why (docs: "CE4 energy" in the physics notes): the
// paper scales the whole pre-peak parabola and the unloading secant by S = -σ tanφ + f c.
// With S depending on σ, the held shear energy S s_p (q² - q³/3) or ½ S |s| changes when
// σ changes at a fixed slip, without any work: slip at σ = 0, compress, slip back under
// compression, release, and the CE4 has given back (q² - q³/3) s_p |σ| tanφ per unit area
// more than it took, every cycle (tests/test_cohesive_energy.cpp); likewise a tensile σ
// lowered S, so closing at a fixed slip made energy. Here the energy held in shear depends
// on s and the state only, the friction is a true Coulomb element (its work past the cap
// is dissipated, as W_res of Eq. 12 says), and tension no longer lowers the shear strength
// (the tension cut-off is Eq. 4's T_s and the mixed damage of Eq. 9). On a monotonic slip
// at constant σ the envelope is the paper's, -σ tanφ + f c, once the friction has slipped
// (|s - s_f| = tanφ|σ|/k_f); before that the pre-peak curve differs.
// Breaking: when D_max = 1 at two or more of the three points the CE4 breaks for good:
// from that step on it has no strength (f = 0 at every point: no tension, no cohesion) but
// it keeps its compression branch and its friction element, so the crack's two faces go
// on resisting overlap and sliding exactly as they did an instant before (status.x = 1,
// "closed"). Contact takes no part between the two triangles of a CE4 that is intact or
// closed (cl_kernels/contact_forces.cl). The CE4 lets go for good (status.x = 2 + the
// step, "released") when every point has opened (o ≥ 0: the branch then holds no energy
// and carries no force, the friction's cap being 0), or when a point has slid past half
// the initial length (the faces no longer face each other: the energy it still holds is
// dissipated, counted in its fracture dissipation). From the next step the two triangles
// are an ordinary contact couple; if they overlap then, the couple waits without force
// until they part (contact_forces.cl), so the hand-over creates no energy. Before
// 2026-12-02 a broken CE4 carried no force at all and its triangles were a contact couple
// from the first step, intact or not: contact added its stiffness to every compressed
// intact CE4 (the blast's P-wave at 50 × E ran 1% faster than the rock's own 5,000 m/s)
// and cost a full overlap evaluation per compressed CE4 (docs/energy-notes.md).
// The time passed to the step is recorded when it breaks.
// In-situ stress (define IN_SITU_GAPS, models with [in_situ]): the law takes o + o₀ and
// s + s₀ at each Gauss point, with o₀ ≤ 0 on the compression branch and s₀ (with the
// friction element's initial slip, gp_slip) set on the host so that at o = s = 0 the
// tractions are the field's, n·σ₀·n and t·σ₀·n (engine/in_situ.cpp). The strengths are
// the law's own: a crack under in-situ compression opens at T_s of total traction. The
// forces stay the gradient of the CE4's potential (the offsets are constants).
// Failure mode: at the step a point's D first reaches 1 it records the opening share of
// Eq. 9, χ = a² / (a² + b²) (1: all opening, 0: all slip). The CE4's χ is the mean over
// its points at D = 1 when it breaks: mode I if χ ≥ 0.9, mode II if χ ≤ 0.1, else mixed.
// The paper names the three damage branches by whether o > o_p and |s| > s_p at all; with
// realistic penalties s_p and o_p are 1e-5 of s_t and o_t, so a nanometre of incidental
// slip would make a 20 µm tensile crack "mixed" (all 40 broken CE4s of the coarse Brazilian
// disc, mesh.size = 3e-3, came out mixed that way; by χ 37 are mode I and 3 mixed). χ
// measures which term of Eq. 9 did the damaging instead.
// Forces: the gradient of the CE4's potential Π = h t Σ_g w_g ψ_g(o_g, s_g) with the state
// frozen (ψ_g the energy per unit area held at point g, below; h the initial length, so
// tractions are per unit reference area): p_g = (σ n + τ t) w_g h t at each point, +p_g to
// face 1 and -p_g to face 2 with the linear shape functions (1-ξ, ξ), plus the frame's
// term: n and t turn with the chord c, do = dδ·n - s (n·dc)/|c|, ds = dδ·t + o (n·dc)/|c|,
// so Π also changes by M (n·dc)/|c| with M = h t Σ_g w_g (τ o - σ s): +m at i and i',
// -m at j and j', m = (M/|c|) n. Without it (the paper's "equal and opposite tractions")
// the two faces' forces act at points δ apart and form a couple -M: a CE4 turned once
// round while sheared and open or overlapping took or gave 2π M (test_cohesive_energy).
// With it the four forces have zero net force and zero net moment, and a rigid motion does
// no work. The paper's current length L in place of h made Π depend on the stretch of the
// faces as well (ψ dL of work from nowhere); h is what Eqs. 6-8 use.
// Energy (per CE4, real4: work W, fracture dissipation, stored, 0):
//   W += ½(A₀+A₁)·Δgap_i + ½(B₀+B₁)·Δgap_j + ½(m₀+m₁)·Δc, the work done on the CE4
//     (trapezoid rule in time on its own four forces, A and B the traction shares of face 1
//     at i and j; the step that breaks it has zero force now); the forces before are the
//     CE4's own slots, so only the gaps and the chord of the last step are kept;
//   stored = h t Σ_g w_g ψ_g, what it would give back if unloaded to o = s = 0 with its
//     state frozen: per unit area
//       normal  o < 0: T_s o² / o_overlap;  o_max > o_p: ½ σ o (secant, Eq. 13);
//               else: f T_s o_p (q² - q³/3), q = o/o_p (the parabola of Eq. 4);
//       shear   s_max > s_p: ½ |τ_c| |s| (secant, Eq. 14);  else f c s_p (q² - q³/3),
//               q = |s|/s_p;  + τ_f² / (2 k_f) in the friction element;
//     zero once broken;
//   fracture dissipation = max over the steps so far of W - stored. With the state frozen
//   the law is the gradient of Π, so W - stored changes only when the state moves: f(D)
//   falls (ψ falls: energy released), the friction element slips (tanφ|σ| |Δs_f|), the
//   CE4 breaks (what it held is released). All of these are ≥ 0, so W - stored never falls
//   but for the trapezoid rule's O(Δ²) error on the curved elastic branches; the max keeps
//   that noise from ever making the dissipation go down (test_cohesive_energy checks
//   W = stored + dissipation to 1e-4 of the CE4's energy scale along random paths).

// Excavation (define EXCAVATION, models with [[excavation]] only; the arguments exist only
// then): excavation_of[e] = the excavations (-1: none) of the CE4's two triangles; its
// factor k is the smaller of theirs (excavation_factor, excavation.cl, at step × dt as the
// triangles take it), so a CE4 in or on the edge of an excavated region is ramped with
// it. Its whole traction (the law's, in-situ offsets included, and the frame's term) and
// its stored energy are scaled by k: its forces are -k ∇Π. While k < 1 its state still
// softens, but it does not break (no status change, no record in the break log: the
// material is leaving, not cracking); once k is 0 at this step and the one before it is
// gone: no force, nothing stored, nothing updated. The energy that leaves with the factor
// is booked like the triangles': excavation_energy[e] = (Π of this step, unscaled;
// Σ (k_before − k_now) ½ (Π_before + Π_now) so far), summed by the host into the
// account's `excavated` term; the CE4's fracture dissipation is W − stored − that sum, so
// ramping dissipates nothing (docs/energy-notes.md, "Excavation").

// The per-CE4 parameter row (COH_*, COH_STRIDE) and the per-property row (COHP_*,
// COHP_STRIDE; `property[e]` names a CE4's) are defined in engine/layouts.hpp.

// f(D) of Eq. 10.
inline real coh_softening(real D, real A, real B, real C) {
  const real ab = A + B;
  // Intact points (most of them, every step): exp(0) = pow(1, C) = 1 exactly, so this is
  // the general formula's own value without its two slow calls.
  if (D == (real)0) return ((real)1 - (ab - (real)1) / ab) * (A + B);
  const real decay = (real)1 - (ab - (real)1) / ab * exp(D * (A + C * B) / (ab * ((real)1 - ab)));
  return decay * (A * ((real)1 - D) + B * pow((real)1 - D, C));
}

// Recoverable energy per unit area under the parabola (2q - q²) peak of Eqs. 4-5 from 0 to
// q = x / x_p: ∫₀^x (2x'/x_p - (x'/x_p)²) peak dx' = peak x_p (q² - q³/3).
inline real coh_parabola_energy(real x, real xp, real peak) {
  const real q = x / xp;
  return peak * xp * q * q * ((real)1 - q / (real)3);
}

// Whether a and b differ in any bit (a store of an unchanged value is skipped: the array
// then holds the same bits as if it had been written; -0 and +0, or two NaNs, differ or
// agree exactly as their bits do).
#ifdef FDEM_DOUBLE
inline bool coh_differ4(real4 a, real4 b) { return any(as_long4(a) != as_long4(b)); }
inline bool coh_differ3(real3 a, real3 b) { return any(as_long3(a) != as_long3(b)); }
#else
inline bool coh_differ4(real4 a, real4 b) { return any(as_int4(a) != as_int4(b)); }
inline bool coh_differ3(real3 a, real3 b) { return any(as_int3(a) != as_int3(b)); }
#endif

// The CE4's frame and its openings and slips at the three Gauss points from its end gaps
// and chord (see the header), with their weighted means (the output's mean opening and
// slip). One function for cohesive_forces and cohesive_output, so both compute the same
// bits.
inline void coh_kinematics(const real2 gap_i, const real2 gap_j, const real2 chord, real* o, real* s,
                           real2* t_out, real2* n_out, real* chord_length_out, real* mean_o_out,
                           real* mean_s_out) {
  const real chord_length = length(chord);
  const real2 t = chord / chord_length;
  const real2 n = (real2)(t.y, -t.x);
  const real r = (real)0.3872983346207417;  // √15 / 10
  const real gauss_xi[3] = {(real)0.5 - r, (real)0.5, (real)0.5 + r};
  const real gauss_w[3] = {(real)5 / (real)18, (real)8 / (real)18, (real)5 / (real)18};
  real mean_o = 0, mean_s = 0;
  for (int g = 0; g < 3; ++g) {
    const real2 delta = ((real)1 - gauss_xi[g]) * gap_i + gauss_xi[g] * gap_j;
    o[g] = dot(delta, n);
    s[g] = dot(delta, t);
    mean_o += gauss_w[g] * o[g];
    mean_s += gauss_w[g] * s[g];
  }
  *t_out = t;
  *n_out = n;
  *chord_length_out = chord_length;
  *mean_o_out = mean_o;
  *mean_s_out = mean_s;
}

// One work-item per CE4: kinematics, law and nodal forces of CE4 `e`; updates its three
// Gauss-point states, its status (broken, mode), its output row and its energy account.
// gp_state: three reals per Gauss point (D_max, o_max [m], max|s| [m]); once D reaches 1
// the first holds 1 + χ, χ the opening share of Eq. 9 at that step (D_max = min(it, 1)):
// D_max stays 1 from then on, so the share needs no word of its own (8 B a point). gp_slip: real4 per CE4, the slip s_f [m] of the friction
// element at each of the three points, and in w the time the CE4 broke [s] (-1 while
// intact). status: int2 per CE4 (broken 0/1, mode 0/1/2/3). Each array is stored only
// where a value changed (the same bits as storing it every step, less traffic).
// energy: three reals per CE4 (work done on it so far, fracture dissipation so far,
// elastic energy it holds now) [J].
// slots: read first (the forces of the last step, for the work), then overwritten.
// The work term needs the end gaps and chord of the last step: the integration moved every
// node by v Δt (cl_kernels/integrate.cl; the halo exchange and the extrinsic copies keep x
// and v together), so x - v Δt gives back the last step's positions (to the bit but where
// the update's rounding was a tie), and the CE4 keeps no copy of them (48 B a CE4 held, 96
// read and written a step). Step 0 moves nothing: the positions are where the set-up
// found them.
// Break catalogue (an append buffer, read by the host with the history rows): a CE4 that
// breaks in this step takes slot k = atomic_inc(break_count) and writes break_ids[k] =
// (e, mode) and break_records[k] = (time, midpoint x, midpoint y of its four nodes, its
// fracture dissipation including this step). The capacity is the number of CE4s and a
// CE4 breaks once, so no record can be lost; the slot order within a step depends on the
// scheduling, so the host sorts what it reads by (time, CE4).
// status_step[0]: step + 1 of the last step in which some CE4's status changed (every
// work-item that changes one writes the same value), for contact_classify, which wakes
// the couples a bond carries only then.

__kernel void cohesive_forces(const uint n_ce4,
                              __global const uint4* restrict ce4_nodes,
                              __global const real* restrict ce4_length,
                              __global const uint* restrict property,
                              __global const real* restrict property_rows,
                              __global const real2* restrict position,
                              __global const real2* restrict velocity,
                              const real dt,
                              const real thickness,
                              const real time,
                              const int step,
                              __global real* restrict gp_state,
                              __global real4* restrict gp_slip,
                              __global int2* restrict status,
                              __global real2* restrict slots,
                              __global real* restrict energy,
                              __global uint* restrict break_count,
                              __global int2* restrict break_ids,
                              __global real4* restrict break_records,
                              __global int* restrict status_step
#ifdef CORNER_FANS
                              , __global const uint* restrict node_origin,
                              __global int* restrict mesh_node_state
#endif
#ifdef IN_SITU_GAPS
                              , __global const real* restrict in_situ_gaps
#endif
#ifdef EXTRINSIC
                              , __global const int* restrict inserted,
                              __global const real4* restrict insertion_gaps
#endif
#ifdef EXCAVATION
                              , __global const int2* restrict excavation_of,
                              __global const real* restrict excavation_time,
                              __global real2* restrict excavation_energy
#endif
#ifdef FLUID_CARRIERS
                              , __global uint* restrict fluid_carriers,
                              __global uint* restrict fluid_carrier_count
#endif
#ifdef ACTIVATE_ON_BREAK
                              , __global const uint2* restrict ce4_triangles,
                              __global uint* restrict active
#endif
                              ) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
#ifdef EXCAVATION
  // k = min of its triangles' factors, now and at the step before (header).
  const int2 dig = excavation_of[e];
  const bool ramped = dig.x >= 0 || dig.y >= 0;
  real keep = (real)1, keep_before = (real)1;
  if (ramped) {
    const real now = (real)step * dt, before = (real)(step - 1) * dt;
    if (dig.x >= 0) keep = excavation_factor(excavation_time, dig.x, now);
    if (dig.y >= 0) keep = fmin(keep, excavation_factor(excavation_time, dig.y, now));
    if (step > 0) {
      if (dig.x >= 0) keep_before = excavation_factor(excavation_time, dig.x, before);
      if (dig.y >= 0) keep_before = fmin(keep_before, excavation_factor(excavation_time, dig.y, before));
    } else {
      keep_before = keep;
    }
    if (keep == (real)0 && keep_before == (real)0) {  // gone: no force, nothing to update
      slots[4 * e] = slots[4 * e + 1] = slots[4 * e + 2] = slots[4 * e + 3] = (real2)(0, 0);
      return;
    }
  }
#endif
#ifdef FDEM_CPU_PREFETCH
  // CPU devices (the host defines it where the device is not a GPU): PoCL runs a group's
  // work-items one after the other, and a CE4's four nodes lie where their triangles are
  // numbered, so each of its eight node reads would wait on memory. CE4 e asks for those
  // of CE4 e + COH_AHEAD while it does its own work. No value changes.
#define COH_AHEAD 16u
  if (e + COH_AHEAD < n_ce4) {
    const uint4 ahead = ce4_nodes[e + COH_AHEAD];
    __builtin_prefetch(position + ahead.x);
    __builtin_prefetch(position + ahead.y);
    __builtin_prefetch(position + ahead.z);
    __builtin_prefetch(position + ahead.w);
    __builtin_prefetch(velocity + ahead.x);
    __builtin_prefetch(velocity + ahead.y);
    __builtin_prefetch(velocity + ahead.z);
    __builtin_prefetch(velocity + ahead.w);
  }
#endif
  const uint4 nd = ce4_nodes[e];  // (i, j, j', i')
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  // End gaps first: differences of nearly equal coordinates are exact, so δ keeps its
  // relative precision however far the CE4 is from the origin.
  const real2 gap_i = xi2 - xi, gap_j = xj2 - xj;
  const real2 chord = (xj - xi) + (xj2 - xi2);
  real o[3], s[3];
  real2 t, n;
  real chord_length, mean_o, mean_s;  // the means are the output's (cohesive_output)
  coh_kinematics(gap_i, gap_j, chord, o, s, &t, &n, &chord_length, &mean_o, &mean_s);
  // The law's opening and slip: the geometric ones, plus with IN_SITU_GAPS the CE4's
  // initial ones (o₀, s₀ per Gauss point: what carries the in-situ field at o = s = 0).
  // The frame's term (moment) and the sliding release use the geometric ones.
#ifdef EXTRINSIC
  // Extrinsic CE4s (cl_kernels/extrinsic.cl): none before insertion (the copies move as
  // one), then the law at o + o₀, s + s₀ (the offsets that carry the traction it took
  // over; 0 for intrinsic CE4s). [in_situ] with extrinsic CE4s is refused by the host.
  if (inserted[e] == 0) {
    slots[4 * e] = slots[4 * e + 1] = slots[4 * e + 2] = slots[4 * e + 3] = (real2)(0, 0);
    return;
  }
  real lo[3], ls[3];
  const real2 offset = insertion_gaps[e].xy;
  for (int g = 0; g < 3; ++g) {
    lo[g] = o[g] + offset.x;
    ls[g] = s[g] + offset.y;
  }
#elif defined(IN_SITU_GAPS)
  real lo[3], ls[3];
  for (int g = 0; g < 3; ++g) {
    lo[g] = o[g] + in_situ_gaps[6 * e + g];
    ls[g] = s[g] + in_situ_gaps[6 * e + 3 + g];
  }
#else
  const real* lo = o;
  const real* ls = s;
#endif

  const real r = (real)0.3872983346207417;  // √15 / 10
  const real gauss_xi[3] = {(real)0.5 - r, (real)0.5, (real)0.5 + r};
  const real gauss_w[3] = {(real)5 / (real)18, (real)8 / (real)18, (real)5 / (real)18};

  int2 st = status[e];
  real2 f_i = (real2)(0, 0), f_j = (real2)(0, 0), f_m = (real2)(0, 0);

  // Intact (0) or closed (1): the law below. Released (≥ 2): no force.
  if (st.x <= 1) {
    const bool closed = st.x == 1;
    __global const real* q = property_rows + COHP_STRIDE * property[e];
    const real h = ce4_length[e];
    const real ot = q[COHP_OT], stl = q[COHP_ST];
    const real Ts = q[COHP_TS], coh = q[COHP_C], tanphi = q[COHP_TANPHI];
    // Eqs. 6-8 as the host wrote them into CohesiveForces::parameters (2 h T_s / P_f, ...):
    // the same operations in the same order, so the same bits (layouts.hpp, COH_*).
    const real op = (real)2 * h * Ts / q[COHP_PO], sp = (real)2 * h * coh / q[COHP_PS];
    const real oov = (real)2 * h * Ts / q[COHP_POV];
    const real A = q[COHP_A], B = q[COHP_B], C = q[COHP_CEXP];
    // Reference area h t: tractions are per unit reference area (see the header).
    const real scale = h * thickness;
    const real k_fric = (real)2 * coh / sp;  // stiffness of the friction element = P_tan / h [Pa/m]
    int at_one = 0;
    real share_sum = 0;
    real held = 0;    // elastic energy per unit reference area, Σ w_g ψ_g
    real moment = 0;  // Σ w_g (τ o - σ s) per unit reference area [N/m]
    bool opened = true;  // every point at o ≥ 0
    real slid = 0;       // largest |s| over the points [m]
    real4 slip_f = gp_slip[e];
    real sf[3] = {slip_f.x, slip_f.y, slip_f.z};
#ifdef FLUID_CARRIERS
    bool softened_before = false, softened = false;  // some point past its peak (D_max > 0), before and after
#endif

    for (int g = 0; g < 3; ++g) {
      const real3 gs_before = vload3(3 * e + g, gp_state);
      real3 gs = gs_before;
      const real og = lo[g], sa = fabs(ls[g]);
      const real over_o = fmax(og - op, (real)0), over_s = fmax(sa - sp, (real)0);
      real D = 0, share = 0;
      if (over_o > (real)0 || over_s > (real)0) {
        const real a = over_o / ot, b = over_s / stl;
        const real d2 = a * a + b * b;
        D = fmin((real)1, sqrt(d2));
        share = a * a / d2;
      }
      if (!closed) {  // a closed CE4's state is frozen: it has no strength left to lose
        // D ≤ 1, so a point at 1 + χ keeps it.
        gs.x = D >= (real)1 && gs.x < (real)1 ? (real)1 + share : fmax(gs.x, D);
        gs.y = fmax(gs.y, og);
        gs.z = fmax(gs.z, sa);
        if (coh_differ3(gs, gs_before)) vstore3(gs, 3 * e + g, gp_state);
      }
      const real d_max = fmin(gs.x, (real)1);
#ifdef FLUID_CARRIERS
      softened_before = softened_before || gs_before.x > (real)0;
      softened = softened || gs.x > (real)0;
#endif
      if (gs.x >= (real)1) {
        share_sum += gs.x - (real)1;
        ++at_one;
      }
      opened = opened && og >= (real)0;
      slid = fmax(slid, fabs(s[g]));

      const real f = closed ? (real)0 : coh_softening(d_max, A, B, C);
      real sigma, held_n;
      if (og < (real)0) {
        sigma = (real)2 * og * Ts / oov;
        held_n = Ts * og * og / oov;
      } else if (gs.y > op && og < gs.y) {
        sigma = f * Ts * og / gs.y;
        held_n = (real)0.5 * sigma * og;
      } else if (og <= op) {
        const real q = og / op;
        sigma = ((real)2 * q - q * q) * f * Ts;
        held_n = coh_parabola_energy(og, op, f * Ts);
      } else {
        sigma = f * Ts;
        held_n = (real)0.5 * sigma * og;
      }

      // Cohesive part of the shear (Eqs. 5 and 14 with the strength f c).
      const real strength = f * coh;
      real tau, held_s;
      if (gs.z > sp && sa < gs.z) {
        tau = strength * sa / gs.z;
        held_s = (real)0.5 * tau * sa;
      } else if (sa <= sp) {
        const real q = sa / sp;
        tau = ((real)2 * q - q * q) * strength;
        held_s = coh_parabola_energy(sa, sp, strength);
      } else {
        tau = strength;
        held_s = (real)0.5 * tau * sa;
      }
      if (ls[g] < (real)0) tau = -tau;

      // Friction part (the -σ tanφ of Eq. 5 under compression): an elastic stick spring of
      // stiffness k_fric on s - s_f, capped at tanφ |σ| (return to the cap moves s_f).
      const real cap = tanphi * fmax(-sigma, (real)0);
      real tau_f = k_fric * (ls[g] - sf[g]);
      if (fabs(tau_f) > cap) {
        tau_f = tau_f > (real)0 ? cap : -cap;
        sf[g] = ls[g] - tau_f / k_fric;
      }
      tau += tau_f;
      held_s += (real)0.5 * tau_f * tau_f / k_fric;

      held += gauss_w[g] * (held_n + held_s);
      moment += gauss_w[g] * (tau * o[g] - sigma * s[g]);
      const real2 pg = (sigma * n + tau * t) * (gauss_w[g] * scale);
      f_i += ((real)1 - gauss_xi[g]) * pg;
      f_j += gauss_xi[g] * pg;
    }
    // The frame's share of the potential's gradient: +m n at i and i', -m n at j and j'
    // (m = M / |c|), which cancels the moment of the traction pairs exactly.
    f_m = (moment * scale / chord_length) * n;

    bool broke_now = false;
#ifdef EXCAVATION
    const bool may_break = keep == (real)1;  // a CE4 being excavated does not break (header)
#else
    const bool may_break = true;
#endif
    if (!closed && at_one >= 2 && may_break) {
      // Breaks: this step's forces become the closed law's (f = 0 at every point: what the
      // third point still held is released, so W - stored only grows).
      const real share = share_sum / (real)at_one;
      st = (int2)(1, share >= (real)0.9 ? 1 : (share <= (real)0.1 ? 2 : 3));
      broke_now = true;
      f_i = f_j = (real2)(0, 0);
      held = 0;
      moment = 0;
      for (int g = 0; g < 3; ++g) {
        const real sigma = lo[g] < (real)0 ? (real)2 * lo[g] * Ts / oov : (real)0;
        const real cap = tanphi * fmax(-sigma, (real)0);
        real tau_f = k_fric * (ls[g] - sf[g]);
        if (fabs(tau_f) > cap) {
          tau_f = tau_f > (real)0 ? cap : -cap;
          sf[g] = ls[g] - tau_f / k_fric;
        }
        held += gauss_w[g] * ((lo[g] < (real)0 ? Ts * lo[g] * lo[g] / oov : (real)0) + (real)0.5 * tau_f * tau_f / k_fric);
        moment += gauss_w[g] * (tau_f * o[g] - sigma * s[g]);
        const real2 pg = (sigma * n + tau_f * t) * (gauss_w[g] * scale);
        f_i += ((real)1 - gauss_xi[g]) * pg;
        f_j += gauss_xi[g] * pg;
      }
      f_m = (moment * scale / chord_length) * n;
    }
    // The slips, and in w the time it broke (this step's when it broke now).
    const real4 slip_now = (real4)(sf[0], sf[1], sf[2], broke_now ? time : slip_f.w);
    if (coh_differ4(slip_now, slip_f)) gp_slip[e] = slip_now;
    // A closed CE4 (or one breaking now) lets go when all its points have opened (no force,
    // nothing held) or one has slid past half its length (what it holds is dissipated).
    if (st.x == 1 && (opened || slid > (real)0.5 * h)) {
      st.x = 2 + step;
      f_i = f_j = f_m = (real2)(0, 0);
      held = 0;
    }
    if (st.x != status[e].x) {
      status[e] = st;
      status_step[0] = step + 1;
    }
#ifdef FLUID_CARRIERS
    // [fluid]: an intact CE4 that starts to carry fluid in this step (it broke, or with
    // FLUID_CARRIERS 2 one of its points softened: fluid_flow.cl's `carries`) joins the
    // fluid stage's list, once (carrying is irreversible; a closed CE4 carries already).
    if (!closed) {
#if FLUID_CARRIERS == 2
      const bool carried = softened_before, carries = st.x >= 1 || softened;
#else
      const bool carried = false, carries = st.x >= 1;
#endif
      if (carries && !carried) fluid_carriers[atomic_inc(fluid_carrier_count)] = e;
    }
#endif
#ifdef EXCAVATION
    // The ramp: the energy that leaves with the factor (trapezoid in time, Π unscaled),
    // then the forces and the stored energy scaled by k.
    real excavated = (real)0;
    if (ramped) {
      const real2 was = excavation_energy[e];  // (Π of the step before, released so far)
      real2 out = was;
      if (step > 0) out.y += (keep_before - keep) * (real)0.5 * (was.x + held * scale);
      out.x = held * scale;
      excavation_energy[e] = out;
      excavated = out.y;
      f_i *= keep;
      f_j *= keep;
      f_m *= keep;
      held *= keep;
    }
#endif

    // Work of this step on the CE4 (trapezoid): with slot_i = A + m, slot_i' = -A + m,
    // slot_j = B - m, slot_j' = -B - m it is ½(A₀+A₁)·Δgap_i + ½(B₀+B₁)·Δgap_j + ½(m₀+m₁)·Δc.
    // The positions of the last step, x - v Δt (header; step 0: where they are), and from
    // them its end gaps and chord by the step's own expressions.
    const real moved_dt = step > 0 ? dt : (real)0;
    const real2 bi = xi - velocity[nd.x] * moved_dt, bj = xj - velocity[nd.y] * moved_dt;
    const real2 bj2 = xj2 - velocity[nd.z] * moved_dt, bi2 = xi2 - velocity[nd.w] * moved_dt;
    const real2 d_gap_i = gap_i - (bi2 - bi), d_gap_j = gap_j - (bj2 - bj);
    const real2 d_chord = chord - ((bj - bi) + (bj2 - bi2));
    const real2 s_i = slots[4 * e], s_j = slots[4 * e + 1], s_j2 = slots[4 * e + 2], s_i2 = slots[4 * e + 3];
    const real2 a_before = (real)0.5 * (s_i - s_i2), b_before = (real)0.5 * (s_j - s_j2);
    const real2 m_before = (real)0.5 * (s_i + s_i2);
    real3 account = vload3(e, energy);
    account.x += (real)0.5 * (dot(a_before + f_i, d_gap_i) + dot(b_before + f_j, d_gap_j) + dot(m_before + f_m, d_chord));
    account.z = held * scale;
#ifdef EXTRINSIC
    // An inserted CE4's stored energy counts from its insertion state (what its law held at
    // the offsets then, insertion_gaps' third value, written by extrinsic_insert).
    account.z -= insertion_gaps[e].z;
#endif
#ifdef IN_SITU_GAPS
    // The field's energy held at the start counts as work done on the CE4 before it (so
    // its fracture dissipation W - stored starts at 0).
    if (step == 0) account.x += account.z;
#endif
    // Fracture dissipation: what the CE4 was given and does not hold. The law cannot
    // create energy (header), so this only moves up, except by the trapezoid rule's error
    // on the elastic curves; the max keeps it from ever moving down.
#ifdef EXCAVATION
    account.y = fmax(account.y, account.x - account.z - excavated);
#else
    account.y = fmax(account.y, account.x - account.z);
#endif
    vstore3(account, e, energy);
#ifdef CORNER_FANS
    // The fans of its two mesh nodes are no longer whole: from the next step contact takes
    // their corner couples (every CE4 breaking at a node in one step writes the same value).
    if (broke_now) {
      const uint2 v = (uint2)(node_origin[nd.x], node_origin[nd.y]);  // its mesh nodes
      if (mesh_node_state[v.x] == 0) mesh_node_state[v.x] = 2 + step;
      if (mesh_node_state[v.y] == 0) mesh_node_state[v.y] = 2 + step;
    }
#endif
#ifdef ACTIVATE_ON_BREAK
    // Activation "fractured" (the work of contact_activation.cl, done where the break
    // happens): its two triangles become contact candidates from the next step, with that
    // step's join stamp, step + 3 (ContactActivation::join_stamp(step + 1)). Every CE4
    // breaking next to a triangle in this step writes the same value.
    if (broke_now) {
      const uint2 pair = ce4_triangles[e];
      if (active[pair.x] == 0u) active[pair.x] = (uint)step + 3u;
      if (active[pair.y] == 0u) active[pair.y] = (uint)step + 3u;
    }
#endif
    if (broke_now) {  // broke in this step: append its record (see the kernel's comment)
      const uint k = atomic_inc(break_count);
      if (k < n_ce4) {
        const real2 mid = (real)0.25 * ((xi + xj) + (xj2 + xi2));
        break_ids[k] = (int2)((int)e, st.y);
        break_records[k] = (real4)(time, mid.x, mid.y, account.y);
      }
    }
  }
  slots[4 * e] = f_i + f_m;
  slots[4 * e + 1] = f_j - f_m;
  slots[4 * e + 2] = -f_j - f_m;
  slots[4 * e + 3] = -f_i + f_m;
}

// One work-item per CE4, for output only (between steps): column 0 the largest D_max over
// its Gauss points, 1 its mean opening [m], 2 its mean slip [m] at the nodes' present
// positions (the frame's: by the same coh_kinematics as cohesive_forces), into `out` (one
// real per CE4, an output array).
__kernel void cohesive_output(const uint n_ce4,
                              const int column,
                              __global const real* restrict gp_state,
                              __global const uint4* restrict ce4_nodes,
                              __global const real2* restrict position,
                              __global real* restrict out) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  if (column == 0) {
    real damage = 0;
    for (int g = 0; g < 3; ++g) damage = fmax(damage, fmin(gp_state[9 * e + 3 * g], (real)1));  // 1 + χ: 1
    out[e] = damage;
    return;
  }
  const uint4 nd = ce4_nodes[e];
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  real o[3], s[3];
  real2 t, n;
  real chord_length, mean_o, mean_s;
  coh_kinematics(xi2 - xi, xj2 - xj, (xj - xi) + (xj2 - xi2), o, s, &t, &n, &chord_length, &mean_o, &mean_s);
  out[e] = column == 1 ? mean_o : mean_s;
}

// One work-item per partial sum k: the fracture dissipation (x) and the stored elastic
// energy (y) of CE4s k, k + P, k + 2P, ... (P = the number of partials), added in that
// fixed order, so the totals the host forms from the partials (again in order) are the
// same on every run.
__kernel void cohesive_energy_partials(const uint n_ce4,
                                       const uint n_partials,
                                       __global const real* restrict energy,
                                       __global real2* restrict partial) {
  const uint k = get_global_id(0);
  if (k >= n_partials) return;
  real2 sum = (real2)(0, 0);
  for (uint e = k; e < n_ce4; e += n_partials) sum += (real2)(energy[3 * e + 1], energy[3 * e + 2]);
  partial[k] = sum;
}
