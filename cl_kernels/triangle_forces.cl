// TRI3 internal forces. One work-item per triangle: the Cauchy stress from the current
// and reference shape (Eq. 1 Neo-Hookean or Eqs. 2-3 hyperelastic, plus the viscous
// η D), and the internal force f_a = -A t σ ∇N_a of its three corners, written to the
// triangle's three corner slots (the node gather sums them; no atomics).
// Inputs: node positions [m] and velocities [m/s]; per triangle the inverse of its
// reference edge matrix X = [x1-x0, x2-x0]. Outputs: corner forces [N]; on request the
// stress (σxx, σyy, σxy [Pa], J).
// Energy account (energy_mode bits; 0 for the output-only stress pass):
//   bit 0, every step: the work the viscous corner forces did over the last step, by the
//     trapezoid rule in time like every other term: ½ (f_before + f_now)·(x_now - x_before)
//     per node, x_now - x_before = v Δt with v the velocity the step's forces use. The
//     triangle keeps A t σ_viscous of the step before (viscous_stress, 3 reals) and takes
//     the positions before as x - v Δt, so f_before·v = -A t σ:L(v) there; f_now·v is
//     -η D:D A t. Minus that work is the viscous dissipation, added to the triangle's own
//     total (viscous_stress .w: no per-step reduction, so it costs no barrier); on energy
//     rows the work-group sums the totals into the group's slot .y. (Only f_now·v, as a first version did, misses half of the
//     change of the viscous force over the step: with critical damping of split
//     fracturable triangles, whose relative modes are near the stable limit, that was
//     the largest term of the balance.) The first step has no "before".
//   bit 1, energy rows: the strain energy of the current shape, W A₀ t, with W the
//     potential whose stress the triangle uses:
//       Eq. 1 (Neo-Hookean): W = μ/2 (F:F - 2 - 2 ln J) + λ/4 (J² - 1 - 2 ln J)
//         (its Cauchy stress is exactly μ/J (B - I) + λ/2 (J - 1/J) I);
//       Eqs. 2-3 (Saint Venant-Kirchhoff): W = ½ E:C:E (Voigt, engineering shear);
//     the group's sum is written to its slot .x. A₀ = ½ det X (X⁻¹ is stored).
// In-situ stress (define IN_SITU_STRESS, models with [in_situ] only; the argument
// initial_stress exists only then): a reference stress S₀ per triangle (the field at its
// reference centroid, as a second Piola-Kirchhoff stress; (S₀xx, S₀yy, S₀xy, 0)) added to
// the material's: σ = σ_el(F) + F S₀ Fᵀ / J, the stress of the potential W_el(F) + S₀:E
// with E = ½(FᵀF - I). At F = I it is S₀ exactly; a rigid turn rotates it with the body
// (objective) and does no work. The strain energy on energy rows includes S₀:E A₀ t (0 at
// the start; docs/energy-notes.md, "In-situ stress").
// Heterogeneous E (define HETEROGENEOUS_YOUNG, models with [material.heterogeneity] on
// "young" only; the arguments exist only then): triangles [young_first, young_first +
// young_count) scale their material's elastic stress and strain energy by their factor
// young_factor[t - young_first] (every elastic constant is proportional to E at a fixed
// ν); the viscosity and the in-situ stress are not scaled.
// Excavation (define EXCAVATION, models with [[excavation]] only; the arguments exist
// only then): triangle t belongs to excavation excavation_of[t] (-1: none), whose factor
// k(time) falls from 1 at start to 0 at start + duration (excavation_time: (start,
// duration) [s] per excavation; duration 0: at once). The triangle's whole stress
// (elastic, in-situ and viscous) is scaled by k, and so is its strain energy; once k is 0
// at this step and the last one the triangle is gone: no force, no energy, and its shape
// no longer matters (it may invert: no inverted-triangle stop). The strain energy that
// leaves with the factor is accounted by the trapezoid rule in time: every step while
// the triangle is still there, excavation_energy[t] = (W A₀ t at this step, Σ (k_before -
// k_now) ½ (W_before + W_now) so far), W the full potential (elastic and in-situ); the
// host sums .y as the account's `excavated` term (docs/energy-notes.md, "Excavation").
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).

// (excavation_factor: cl_kernels/excavation.cl, built ahead of this file with EXCAVATION.)

inline real4 neo_hookean_stress(real4 F, real J, real lambda, real mu) {
  // σ = λ/2 (J - 1/J) I + μ/J (F Fᵀ - I)
  const real4 B = mul2(F, transpose2(F));
  const real p = (real)0.5 * lambda * (J - (real)1 / J);
  const real s = mu / J;
  return (real4)(p + s * (B.x - (real)1), s * B.y, s * B.z, p + s * (B.w - (real)1));
}

// a - ln(1 + a), accurate for small a too: the series below |a| = 1e-3 (its first
// omitted term is 1e-18 relative), the direct form above it.
inline real log1p_gap(real a) {
  if (fabs(a) < (real)1e-3)
    return a * a * ((real)0.5 - a * ((real)1 / (real)3 - a * ((real)0.25 - a * ((real)0.2 - a / (real)6))));
  return a - log1p(a);
}

// Strain energy per unit reference area of Eq. 1's potential,
//   W = μ/2 (F:F - 2 - 2 ln J) + λ/4 (J² - 1 - 2 ln J),
// written in the displacement gradient H = F - I so that small strains do not cancel
// (F:F - 2 and 2 ln J are both ≈ 2 tr H; their difference is second order): with
// a = J - 1 = tr H + det H,
//   F:F - 2 - 2 ln J = H:H - 2 det H + 2 (a - ln(1 + a)),
//   J² - 1 - 2 ln J  = a² + 2 (a - ln(1 + a)).
inline real neo_hookean_energy(real4 F, real lambda, real mu) {
  const real4 H = F - (real4)(1, 0, 0, 1);
  const real a = (H.x + H.w) + det2(H);
  const real gap = (real)2 * log1p_gap(a);
  const real hh = H.x * H.x + H.y * H.y + H.z * H.z + H.w * H.w;
  return (real)0.5 * mu * (hh - (real)2 * det2(H) + gap) + (real)0.25 * lambda * (a * a + gap);
}

// Strain energy per unit reference area of Eqs. 2-3: ½ E:C:E, with E = ½(H + Hᵀ + HᵀH)
// from H = F - I (no cancellation at small strain).
inline real hyperelastic_energy(real4 F, __global const real* m) {
  const real4 H = F - (real4)(1, 0, 0, 1);
  const real4 HtH = mul2(transpose2(H), H);
  const real exx = H.x + (real)0.5 * HtH.x;
  const real eyy = H.w + (real)0.5 * HtH.w;
  const real gxy = H.y + H.z + HtH.y;  // engineering shear 2 E_xy
  const real sxx = m[MAT_C11] * exx + m[MAT_C12] * eyy + m[MAT_C16] * gxy;
  const real syy = m[MAT_C12] * exx + m[MAT_C22] * eyy + m[MAT_C26] * gxy;
  const real sxy = m[MAT_C16] * exx + m[MAT_C26] * eyy + m[MAT_C66] * gxy;
  return (real)0.5 * (exx * sxx + eyy * syy + gxy * sxy);
}

inline real4 hyperelastic_stress(real4 F, real J, __global const real* m) {
  // Green-Lagrange E = ½(FᵀF - I); S = C : E in Voigt form; σ = F S Fᵀ / J
  const real4 Ct = mul2(transpose2(F), F);
  const real exx = (real)0.5 * (Ct.x - (real)1);
  const real eyy = (real)0.5 * (Ct.w - (real)1);
  const real gxy = Ct.y;  // engineering shear 2 E_xy
  const real sxx = m[MAT_C11] * exx + m[MAT_C12] * eyy + m[MAT_C16] * gxy;
  const real syy = m[MAT_C12] * exx + m[MAT_C22] * eyy + m[MAT_C26] * gxy;
  const real sxy = m[MAT_C16] * exx + m[MAT_C26] * eyy + m[MAT_C66] * gxy;
  const real4 S = (real4)(sxx, sxy, sxy, syy);
  const real4 sigma = mul2(mul2(F, S), transpose2(F));
  return sigma / J;
}

// Triangle t's corner forces; returns (strain energy on energy rows, the triangle's viscous
// dissipation so far, 0, 0).
inline real4 triangle(const uint t,
                        __global const uint* restrict tri_nodes,
                        __global const real4* restrict ref_inverse,
                        __global const uint* restrict tri_material,
                        __global const real* restrict materials,
                        __global const real2* restrict position,
                        __global const real2* restrict velocity,
                        const real thickness,
                        const int write_stress,
                        const int step,
                        __global real2* restrict corner_force,
                        __global real4* restrict stress,
                        __global int* restrict conditions,
                        const int energy_mode,
                        const real dt,
                        __global real4* restrict viscous_stress
#ifdef IN_SITU_STRESS
                        , __global const real4* restrict initial_stress
#endif
#ifdef HETEROGENEOUS_YOUNG
                        , __global const real* restrict young_factor, const uint young_first, const uint young_count
#endif
#ifdef EXCAVATION
                        , __global const int* restrict excavation_of, __global const real* restrict excavation_time,
                        __global real2* restrict excavation_energy
#endif
                        ) {
  const uint n0 = tri_nodes[3 * t], n1 = tri_nodes[3 * t + 1], n2 = tri_nodes[3 * t + 2];
  const real2 x0 = position[n0], x1 = position[n1], x2 = position[n2];
  const real2 e1 = x1 - x0, e2 = x2 - x0;
  const real4 Dx = (real4)(e1.x, e2.x, e1.y, e2.y);  // current edge matrix, columns e1, e2
  const real4 F = mul2(Dx, ref_inverse[t]);
  const real J = det2(F);
  __global const real* m = materials + MATERIAL_STRIDE * tri_material[t];

#ifdef EXCAVATION
  const int dig = excavation_of[t];
  real keep = (real)1, keep_before = (real)1;
  if (dig >= 0) {
    keep = excavation_factor(excavation_time, dig, (real)step * dt);
    keep_before = step > 0 ? excavation_factor(excavation_time, dig, (real)(step - 1) * dt) : keep;
    if (keep == (real)0 && keep_before == (real)0) {  // gone
      corner_force[3 * t] = corner_force[3 * t + 1] = corner_force[3 * t + 2] = (real2)(0, 0);
      if (write_stress) stress[t] = (real4)(0, 0, 0, J);
      return (real4)(0, 0, 0, 0);
    }
  }
  const bool excavating = dig >= 0;  // still there, maybe on its way out
#else
  const bool excavating = false;
#endif

  if (!(J > (real)0)) {  // inverted, degenerate, or NaN
    atomic_min(&conditions[COND_INVERTED_TRI], (int)t);
    atomic_min(&conditions[COND_INVERTED_STEP], step);
    corner_force[3 * t] = corner_force[3 * t + 1] = corner_force[3 * t + 2] = (real2)(0, 0);
    return (real4)(0, 0, 0, 0);
  }

  real4 sigma = (m[MAT_MODEL] == (real)0) ? neo_hookean_stress(F, J, m[MAT_LAMBDA], m[MAT_MU])
                                    : hyperelastic_stress(F, J, m);
#ifdef HETEROGENEOUS_YOUNG
  const real young = (t - young_first < young_count) ? young_factor[t - young_first] : (real)1;
  sigma *= young;
#endif

  // Current shape-function gradients: rows of Dx⁻¹ are ∇N1, ∇N2; ∇N0 = -(∇N1 + ∇N2).
  const real4 Dinv = inverse2(Dx);
  const real2 g1 = (real2)(Dinv.x, Dinv.y), g2 = (real2)(Dinv.z, Dinv.w);
  const real2 g0 = -(g1 + g2);

#ifdef IN_SITU_STRESS
  const real4 s0 = initial_stress[t];
  sigma += mul2(mul2(F, (real4)(s0.x, s0.z, s0.z, s0.y)), transpose2(F)) / J;
#endif

  const real area_t = (real)0.5 * det2(Dx) * thickness;  // current area × thickness
  real4 energy = (real4)(0, 0, 0, 0);
  if ((energy_mode & 2) != 0 || excavating)
    energy.x = (real)0.5 / det2(ref_inverse[t]) * thickness *
               ((m[MAT_MODEL] == (real)0) ? neo_hookean_energy(F, m[MAT_LAMBDA], m[MAT_MU]) : hyperelastic_energy(F, m));
#ifdef HETEROGENEOUS_YOUNG
  energy.x *= young;
#endif
#ifdef IN_SITU_STRESS
  if ((energy_mode & 2) != 0 || excavating) {  // S₀:E A₀ t, E = ½(H + Hᵀ + HᵀH) from H = F - I
    const real4 H = F - (real4)(1, 0, 0, 1);
    const real4 HtH = mul2(transpose2(H), H);
    const real exx = H.x + (real)0.5 * HtH.x, eyy = H.w + (real)0.5 * HtH.w, gxy = H.y + H.z + HtH.y;
    energy.x += (real)0.5 / det2(ref_inverse[t]) * thickness * (s0.x * exx + s0.y * eyy + s0.z * gxy);
  }
#endif
#ifdef EXCAVATION
  if (excavating) {
    if (!write_stress) {  // a force step (the output's stress pass repeats a step: no account)
      real2 out = excavation_energy[t];  // (W of the step before, released so far)
      if (step > 0) out.y += (keep_before - keep) * (real)0.5 * (out.x + energy.x);
      out.x = energy.x;
      excavation_energy[t] = out;
    }
    energy.x *= keep;
    sigma *= keep;
  }
  const real eta = keep * m[MAT_VISCOSITY];
#else
  const real eta = m[MAT_VISCOSITY];
#endif
  if (eta != (real)0) {
    // L = Σ v_a ⊗ ∇N_a; D = sym(L)
    const real2 v0 = velocity[n0], v1 = velocity[n1], v2 = velocity[n2];
    const real lxx = v0.x * g0.x + v1.x * g1.x + v2.x * g2.x;
    const real lxy = v0.x * g0.y + v1.x * g1.y + v2.x * g2.y;
    const real lyx = v0.y * g0.x + v1.y * g1.x + v2.y * g2.x;
    const real lyy = v0.y * g0.y + v1.y * g1.y + v2.y * g2.y;
    const real dxy = (real)0.5 * (lxy + lyx);
    sigma += eta * (real4)(lxx, dxy, dxy, lyy);
    if ((energy_mode & 1) != 0) {
      const real now = eta * (lxx * lxx + lyy * lyy + (real)2 * dxy * dxy) * area_t;  // -f_now·v
      real before = (real)0;                                                          // -f_before·v
      if (step > 0) {
        const real4 s = viscous_stress[t];  // (A t σxx, A t σyy, A t σxy) of the step before, total
        const real2 p0 = x0 - v0 * dt, p1 = x1 - v1 * dt, p2 = x2 - v2 * dt;
        const real4 Pinv = inverse2((real4)(p1.x - p0.x, p2.x - p0.x, p1.y - p0.y, p2.y - p0.y));
        const real2 h1 = (real2)(Pinv.x, Pinv.y), h2 = (real2)(Pinv.z, Pinv.w), h0 = -(h1 + h2);
        const real kxx = v0.x * h0.x + v1.x * h1.x + v2.x * h2.x;
        const real kxy = v0.x * h0.y + v1.x * h1.y + v2.x * h2.y;
        const real kyx = v0.y * h0.x + v1.y * h1.x + v2.y * h2.x;
        const real kyy = v0.y * h0.y + v1.y * h1.y + v2.y * h2.y;
        before = s.x * kxx + s.y * kyy + s.z * (kxy + kyx);
        energy.y = (real)0.5 * (before + now) * dt;
      }
      const real total = viscous_stress[t].w + energy.y;  // this triangle's dissipation so far
      viscous_stress[t] = (real4)(area_t * eta * lxx, area_t * eta * lyy, area_t * eta * dxy, total);
      energy.y = total;
    }
  }

  // f_a = -A t σ ∇N_a
  corner_force[3 * t] = -area_t * (real2)(sigma.x * g0.x + sigma.y * g0.y, sigma.z * g0.x + sigma.w * g0.y);
  corner_force[3 * t + 1] = -area_t * (real2)(sigma.x * g1.x + sigma.y * g1.y, sigma.z * g1.x + sigma.w * g1.y);
  corner_force[3 * t + 2] = -area_t * (real2)(sigma.x * g2.x + sigma.y * g2.y, sigma.z * g2.x + sigma.w * g2.y);
  if (write_stress) stress[t] = (real4)(sigma.x, sigma.w, (real)0.5 * (sigma.y + sigma.z), J);
  return energy;
}

// One work-item per triangle t: its three corner forces and its share of the energy
// account (see the top of this file).
__kernel void triangle_forces(const uint n_triangles,
                              __global const uint* restrict tri_nodes,
                              __global const real4* restrict ref_inverse,
                              __global const uint* restrict tri_material,
                              __global const real* restrict materials,
                              __global const real2* restrict position,
                              __global const real2* restrict velocity,
                              const real thickness,
                              const int write_stress,
                              const int step,
                              __global real2* restrict corner_force,
                              __global real4* restrict stress,
                              __global int* restrict conditions,
                              const int energy_mode,
                              const real dt,
                              __global real2* restrict group_energy,
                              __global real4* restrict viscous_stress,
                              const int item_rows,
                              __global real2* restrict triangle_energy,
                              __global real* restrict energy_partials
#ifdef IN_SITU_STRESS
                              , __global const real4* restrict initial_stress
#endif
#ifdef HETEROGENEOUS_YOUNG
                              , __global const real* restrict young_factor, const uint young_first,
                              const uint young_count
#endif
#ifdef EXCAVATION
                              , __global const int* restrict excavation_of,
                              __global const real* restrict excavation_time, __global real2* restrict excavation_energy
#endif
#ifdef BOUNDARY_TAIL
                              , const uint triangle_groups, const uint n_edges, BOUNDARY_EDGE_ARGS
#endif
#ifdef FLUID_HEAD
                              , const uint fluid_head, FLUID_STEP_ARGS
#endif
                              ) {
  __local real4 energy_scratch[GROUP_SIZE];
#ifdef FLUID_HEAD
  // The liquid's step in the same launch (FluidFlow's fused step as its first work-group,
  // fluid_head = 1; 0 on the output's stress pass): one compute unit walks the network
  // while the others take the triangles, which neither read what it writes nor write
  // what it reads (fluid_flow.cl, built ahead of this file). Its local copies are the
  // energy scratch's bytes (2 × FLUID_GROUP real2 = GROUP_SIZE real4).
#if FLUID_GROUP != GROUP_SIZE
#error "FLUID_HEAD needs the fluid's work-group to be the triangle stage's"
#endif
  __local real fluid_hole_local[3];
  __local uint fluid_too_many;
  if (get_group_id(0) < fluid_head) {  // the whole group: no barrier below is skipped by part of one
    fluid_step(position, thickness, step, dt, FLUID_STEP_PASS, fluid_hole_local, (__local real2*)energy_scratch,
               &fluid_too_many);
    return;
  }
  const uint group = get_group_id(0) - fluid_head;
  const uint t = get_global_id(0) - fluid_head * GROUP_SIZE;
#else
  const uint group = get_group_id(0);
  const uint t = get_global_id(0);
#endif
#ifdef BOUNDARY_TAIL
  // The boundary loads in the same launch (BoundaryLoads fused into TriangleForces: one
  // launch a step less): the work-groups after the triangles' take one loaded edge a
  // work-item, as boundary_loads does (boundary_loads.cl, built ahead of this file). A
  // whole group leaves here, so no barrier below is skipped by part of one.
  if (group >= triangle_groups) {
    const uint e = t - triangle_groups * GROUP_SIZE;
    if (e < n_edges)
      boundary_edge(e, materials, position, velocity, thickness, dt, step, BOUNDARY_EDGE_PASS);
    return;
  }
#endif
  real4 energy = (real4)(0, 0, 0, 0);
  if (t < n_triangles)
    energy = triangle(t, tri_nodes, ref_inverse, tri_material, materials, position, velocity, thickness, write_stress,
                      step, corner_force, stress, conditions, energy_mode, dt, viscous_stress
#ifdef IN_SITU_STRESS
                      , initial_stress
#endif
#ifdef HETEROGENEOUS_YOUNG
                      , young_factor, young_first, young_count
#endif
#ifdef EXCAVATION
                      , excavation_of, excavation_time, excavation_energy
#endif
                      );
  // Energy rows: the triangle's own (strain energy, viscous dissipation so far), summed
  // in triangle order (rank-independent sums, engine/energy.hpp): over each block of
  // ORDERED_BLOCK triangles left to right into energy_partials (2 reals a block), what
  // ordered_block_sums (ordered_sum.cl) does, by the first work-item of the block (the
  // work-group, GROUP_SIZE, holds whole blocks); per triangle only where item_rows is 1
  // (a split run, whose energy() gathers the values per triangle).
  const real2 terms = (real2)(energy.x, (energy_mode & 1) ? energy.y : (real)0);
  if ((energy_mode & 2) && item_rows && t < n_triangles) triangle_energy[t] = terms;
  if (energy_mode & 2) {  // the same for every work-item: no barrier is skipped by some only
    // The ordered block sums first: the triangle's terms go to local memory right after
    // the region that computed them (as in integrate.cl).
    const uint lid = get_local_id(0);
    energy_scratch[lid] = (real4)(terms, (real)0, (real)0);
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid % ORDERED_BLOCK == 0 && t < n_triangles) {
      const uint count = min((uint)ORDERED_BLOCK, n_triangles - t);
      real2 block = (real2)(0, 0);
      for (uint k = 0; k < count; ++k) block += energy_scratch[lid + k].xy;
      vstore2(block, t / ORDERED_BLOCK, energy_partials);
    }
    barrier(CLK_LOCAL_MEM_FENCE);  // the blocks are summed before the scratch is reused
    const real4 sum = group_sum4(energy_scratch, energy);
    if (lid == 0) {
      real2 slot = group_energy[group];
      slot.x = sum.x;
      if (energy_mode & 1) slot.y = sum.y;
      group_energy[group] = slot;
    }
  }
}
