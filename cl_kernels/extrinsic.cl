// Extrinsic cohesive elements (ECZM; `fracture.model = "extrinsic"`, docs/energy-notes.md
// "Extrinsic cohesive elements"). The mesh is split as for intrinsic CE4s (every
// fracturable triangle has its own three nodes, every interior edge a CE4), but an
// extrinsic CE4 carries nothing until it is inserted: before that, the copies of a mesh
// vertex joined through uninserted CE4s move as one body. Two kernels run after the
// integration (engine/stages/extrinsic.cpp):
//
// extrinsic_tie, one work-item per mesh vertex that has an extrinsic CE4 at it: its copies
//   (nodes, in node order) and its links (two copies joined by one end of a CE4, with the
//   CE4) come from the host. The copies joined through links whose CE4 is not inserted
//   form runs (connected components: each copy takes the smallest copy index of its run by
//   relaxing the links to a fixed point, at most one pass per copy); each run's velocities
//   and positions are replaced by their mass-weighted means, summed over the run in copy
//   order relative to its first copy. The integration gave each copy v⁺ = v⁻ + f/m Δt;
//   copies that share v⁻ and x (they did after the last step's tie) then end with exactly
//   the cluster's step, v⁺ = v⁻ + Σf/Σm Δt, x⁺ = x + v⁺ Δt. Each work-item writes only its
//   own vertex's copies, in a fixed order: no atomics, the same bits on any device and
//   work-group size. Fast path: `whole` per vertex, bit 0 from the host (the vertex's links
//   join every copy), bit 1 set by extrinsic_insert when it inserts a CE4 at the vertex
//   (and by extrinsic_mark after a checkpoint's flags are loaded). While it is exactly 1,
//   all copies are one run, and the sums are taken straight over them in copy order, the
//   same operations as the labelled path's run of copy 0, without reading the links or
//   relaxing labels (H200, 1.08M TRI3, nothing inserted: 0.600 ms a step for the tie with
//   the relaxation at every vertex). A model with extrinsic CE4s numbers its nodes by mesh
//   vertex (engine/model/model.cpp, split_fracturable): a vertex's copies are consecutive
//   nodes, and neighbouring work-items read neighbouring runs of memory (0.515 → 0.151 ms
//   at 1.08M against the triangle-by-triangle numbering of intrinsic models).
// extrinsic_insert, one work-item per CE4 (order-free: it reads the triangles' forces of
//   this step and writes only its own CE4): for a CE4 not yet inserted, the traction on
//   its edge t = σ̄·n, σ̄ the mean of its two triangles' stresses. A triangle's corner
//   force is f_k = -A t σ ∇N_k = ½ t L σ n_k (n_k the outward normal of the edge opposite
//   corner k, L its current length), so σ n_k = 2 f_k / (t L): the corner opposite the
//   CE4's edge gives the traction on it with no stress evaluation (any material law,
//   viscous stress included, as the forces the triangle applies). With n the CE4's normal
//   (away from triangle 1) the mean traction is f_k1 / (t L1) - f_k2 / (t L2). Normal part
//   σ_n = t·n, shear τ = t·t (t along the chord). It inserts when the intrinsic law's peak
//   envelope is reached: σ_n ≥ T_s, or |τ| ≥ c + tanφ max(0, -σ_n) (the cohesive peak c
//   plus the friction element's cap; cl_kernels/cohesive_forces.cl). Inserted, the CE4 takes
//   per-CE4 offsets (o₀, s₀) of its law's opening and slip (and its friction element's slip
//   s_f) such that at zero gap its tractions are the carried ones, capped at the peak:
//   σ_n ≥ 0: o₀ = o_p (1 - √(1 - min(σ_n, T_s)/T_s)) (the parabola of Eq. 4 inverted; o_p
//   at the peak), σ_n < 0: o₀ = σ_n o_overlap / (2 T_s) (the compression branch);
//   cohesive shear τ_c = sgn(τ) min(|τ|, c), s₀ from the parabola of Eq. 5 the same way;
//   the rest τ - τ_c, within ±tanφ max(0, -σ_n), to the friction element: s_f = s₀ - τ_f / k_f.
//   So an edge inserted in tension starts at o = o_p, the peak, and only softens as it
//   opens (D grows from 0 past o_p). Its insertion row's third value takes ψ₀ h t, the energy its law
//   holds at the offsets, which cohesive_forces.cl subtracts from the stored energy: an
//   inserted CE4's stored energy is counted from the state it was inserted in, so the
//   insertion itself adds nothing to the account. inserted_count counts insertions
//   (integer atomic; its total does not depend on the order).
// A third, extrinsic_mark, runs once when a checkpoint is loaded: it rebuilds the tie's
// per-vertex `whole` bits from the loaded flags.

__kernel void extrinsic_tie(const uint n_vertices,
                            __global const uint* restrict copy_start,
                            __global const uint* restrict copy_node,
                            __global const uint* restrict link_start,
                            __global const uint4* restrict link,
                            __global const uchar* restrict whole,
                            __global const int* restrict inserted,
                            __global const real* restrict node_mass,
                            __global real2* restrict position,
                            __global real2* restrict velocity) {
  const uint v = get_global_id(0);
  if (v >= n_vertices) return;
  const uint first = copy_start[v], n = copy_start[v + 1] - first;
  if (whole[v] == 1) {
    if (n < 2) return;
    const uint a = copy_node[first];
    const real2 x0 = position[a], v0 = velocity[a];
    real mass = 0;
    real2 dx = (real2)(0, 0), dv = (real2)(0, 0);
    for (uint q = 0; q < n; ++q) {
      const uint b = copy_node[first + q];
      const real m = node_mass[b];
      mass += m;
      dx += m * (position[b] - x0);
      dv += m * (velocity[b] - v0);
    }
    const real2 x = x0 + dx / mass, vel = v0 + dv / mass;
    for (uint q = 0; q < n; ++q) {
      const uint b = copy_node[first + q];
      position[b] = x;
      velocity[b] = vel;
    }
    return;
  }
  const uint l0 = link_start[v], l1 = link_start[v + 1];
  uchar label[EXTRINSIC_MAX_COPIES];
  for (uint k = 0; k < n; ++k) label[k] = (uchar)k;
  bool changed = true;
  while (changed) {  // at most n passes: each pass that changes lowers some label
    changed = false;
    for (uint l = l0; l < l1; ++l) {
      const uint4 lk = link[l];
      if (inserted[lk.z] != 0) continue;
      const uchar m = min(label[lk.x], label[lk.y]);
      if (label[lk.x] != m || label[lk.y] != m) {
        label[lk.x] = m;
        label[lk.y] = m;
        changed = true;
      }
    }
  }
  for (uint k = 0; k < n; ++k) {
    if (label[k] != k) continue;  // k is the first copy of its run
    const uint a = copy_node[first + k];
    const real2 x0 = position[a], v0 = velocity[a];
    real mass = 0;
    real2 dx = (real2)(0, 0), dv = (real2)(0, 0);
    uint members = 0;
    for (uint q = k; q < n; ++q) {
      if (label[q] != k) continue;
      const uint b = copy_node[first + q];
      const real m = node_mass[b];
      mass += m;
      dx += m * (position[b] - x0);
      dv += m * (velocity[b] - v0);
      ++members;
    }
    if (members < 2) continue;
    const real2 x = x0 + dx / mass, vel = v0 + dv / mass;
    for (uint q = k; q < n; ++q) {
      if (label[q] != k) continue;
      const uint b = copy_node[first + q];
      position[b] = x;
      velocity[b] = vel;
    }
  }
}

// One work-item per tie vertex: sets bit 1 of whole where a CE4 at the vertex is inserted
// (after a checkpoint's flags were loaded; the insertion marks its own as it goes).
__kernel void extrinsic_mark(const uint n_vertices,
                             __global const uint* restrict link_start,
                             __global const uint4* restrict link,
                             __global const int* restrict inserted,
                             __global uchar* restrict whole) {
  const uint v = get_global_id(0);
  if (v >= n_vertices) return;
  uchar any = 0;
  for (uint l = link_start[v]; l < link_start[v + 1]; ++l) any |= inserted[link[l].z] != 0 ? 2 : 0;
  whole[v] = (uchar)((whole[v] & 1) | any);
}

// opposite: per CE4 the corner-force slots (3 t + k) of the corners opposite its edge in
// triangle 1 and in triangle 2. gaps: per CE4 (o₀, s₀) [m] and ψ₀ h t [J], the energy its
// law holds at the offsets (cohesive_forces.cl counts the stored energy from it).
// gp_slip: its friction slips (and in w the break time, -1 while intact).
__kernel void extrinsic_insert(const uint n_ce4,
                               __global const uint4* restrict ce4_nodes,
                               __global const real* restrict ce4_length,
                               __global const uint* restrict property,
                               __global const real* restrict property_rows,
                               __global const uint2* restrict opposite,
                               __global const real2* restrict position,
                               __global const real2* restrict corner_force,
                               const real thickness,
                               __global int* restrict inserted,
                               __global real4* restrict gaps,
                               __global real4* restrict gp_slip,
                               __global uint* restrict inserted_count,
                               __global const uint2* restrict ce4_vertex,
                               __global uchar* restrict whole) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  if (inserted[e] != 0) return;
  const uint4 nd = ce4_nodes[e];
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  const real2 chord = (xj - xi) + (xj2 - xi2);
  const real2 t = chord / length(chord);
  const real2 n = (real2)(t.y, -t.x);
  const uint2 opp = opposite[e];
  const real2 traction =
      corner_force[opp.x] / (thickness * length(xj - xi)) - corner_force[opp.y] / (thickness * length(xj2 - xi2));
  const real sn = dot(traction, n), tau = dot(traction, t);

  __global const real* q = property_rows + COHP_STRIDE * property[e];
  const real h = ce4_length[e];
  const real Ts = q[COHP_TS], coh = q[COHP_C], tanphi = q[COHP_TANPHI];
  // o_p, s_p, o_overlap as cohesive_forces.cl forms them (the same operations).
  const real op = (real)2 * h * Ts / q[COHP_PO], sp = (real)2 * h * coh / q[COHP_PS];
  const real oov = (real)2 * h * Ts / q[COHP_POV];
  const real cap = tanphi * fmax(-sn, (real)0);
  if (!(sn >= Ts || fabs(tau) >= coh + cap)) return;

  const real sn_c = fmin(sn, Ts);
  real o0, held_n;
  if (sn_c >= (real)0) {
    const real r = (real)1 - sqrt((real)1 - sn_c / Ts);
    o0 = r * op;
    held_n = Ts * op * r * r * ((real)1 - r / (real)3);
  } else {
    o0 = sn_c * oov / ((real)2 * Ts);
    held_n = Ts * o0 * o0 / oov;
  }
  const real tau_c = copysign(fmin(fabs(tau), coh), tau);
  const real rs = (real)1 - sqrt((real)1 - fabs(tau_c) / coh);
  const real s0 = copysign(rs * sp, tau);
  const real k_fric = (real)2 * coh / sp;
  const real tau_f = clamp(tau - tau_c, -cap, cap);
  const real sf = s0 - tau_f / k_fric;
  const real held_s = coh * sp * rs * rs * ((real)1 - rs / (real)3) + (real)0.5 * tau_f * tau_f / k_fric;

  inserted[e] = 1;
  // The tie's fast path ends at both ends' vertices. Every work-item that writes a vertex's
  // byte writes the same value (its bit 0 never changes), so no atomic is needed.
  const uint2 ends = ce4_vertex[e];
  whole[ends.x] = (uchar)(whole[ends.x] | 2);
  whole[ends.y] = (uchar)(whole[ends.y] | 2);
  gaps[e] = (real4)(o0, s0, (held_n + held_s) * h * thickness, (real)0);
  gp_slip[e] = (real4)(sf, sf, sf, gp_slip[e].w);
  atomic_inc(inserted_count);
}
