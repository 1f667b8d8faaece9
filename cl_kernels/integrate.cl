// Central-difference step. One work-item per node:
//   f   = Σ element and load forces + m g               (gravity uses the true mass)
//   f_d = f - α |f| sgn(v), per component               (Cundall local damping, Eq. 18)
//   v  += f_d / m_inertia · Δt                           (m_inertia scaled or true)
//   prescribed components of v overwrite it (ramped over their rise time)
//   x  += v Δt
// node_force is overwritten with f, the node's out-of-balance force, which the host
// reads for history (max unbalanced force, reactions on constrained regions).
// bc_table per group: (mask, vx, vy, rise); mask bit 0 = x prescribed, bit 1 = y.
//
// With a contact skin (SKIN_TEST 1, a define from the host) the step also takes the skin
// test of the next step's contact stage (engine/stages/contact_skin.hpp explains it): the
// node's move since the last detection and its speed, the work-group's largest of each
// folded into words RING_MOVED and RING_SPEED of slot `slot` of the monitor ring with
// integer atomic_max on float bits, and global work-item 0 clears slot `next_slot`.
// Doing it here saves a launch and a pass over the nodes.
// Energy account (docs/case-format.md defines every term). The step's velocities before
// (v⁻ = v at t - Δt/2) and after (v⁺ = v at t + Δt/2) are both here, so the account is
// exact for the leapfrog: with the total nodal force F = m (v⁺ - v⁻)/Δt, Σ_steps F·v̄ Δt
// (v̄ = (v⁻ + v⁺)/2) equals the change of ½ m v⁻·v⁺, the kinetic energy at the step's
// own time t (positions x). Per node and component:
//   free:        the local damping force (f_d - f) works (f_d - f)·v̄ Δt (dissipated: minus it);
//   prescribed:  the reaction R = m (v⁺ - v⁻)/Δt - f that keeps the path works R·v̄ Δt
//                (boundary work, supplied).
// Each node adds both to its own total in node_work (only nodes where they are not zero
// write: free nodes without local damping cost nothing, and there is no per-step
// reduction). The very first step counts only its forward half (F·v⁺/2 Δt), so the totals
// are the trapezoid rule in time from t = 0. On an energy row (energy_row = 1) the
// work-group sums the totals into group_work (group_sum4, a fixed order) and writes to
// group_row: Σ ½ m v⁻·v⁺
// (kinetic, inertia masses), Σ -m g·(x - X) (gravity potential, true masses, relative to
// the reference positions X), and the forward halves F·v⁺/2 Δt of this step's damping and
// reaction work, which the host subtracts so that the row's works run to t exactly.
// With GATHER_IN_STEP 1 the step first sums the node's force itself (gathered_sum of
// cl_kernels/node_gather.cl, with its GATHER_* defines) instead of reading what
// gather_node_sums wrote: one launch less a step, and no round trip of node_force through
// memory between the two. The sum and everything after it are the same expressions, so
// the result is the same bits.
// node_mass: with MASS_SCALING 1 real2 (true mass, inertia); with 0 one real, the mass,
// which is also the inertia (LumpedMass: half the bytes when nothing is scaled).
// Energy rows' ordered sums: the node's terms (kinetic, gravity potential, damping work
// and reaction work up to t) summed over each block of ORDERED_BLOCK nodes left to right,
// which is what ordered_block_sums (ordered_sum.cl) does, into energy_partials (4 reals a
// block): the work-group (GROUP_SIZE, a multiple of ORDERED_BLOCK) puts its nodes' terms in
// local memory and the first work-item of each block adds them in node order, so the
// per-node array exists only where node_rows is 1 (a split run, whose energy() gathers the
// values per node).
// WORK_ROWS_BY_GROUP 1 (no local damping, so only nodes with a prescribed group do work):
// node_work has a row only for each such node, and bc_group holds the group in its low
// 8 bits and the node's row in the upper 24 (Integrate::work_rows); the other nodes' totals
// are +0, what their rows held (a free node's terms are the same bits either way).
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two), SKIN_TEST,
// GATHER_IN_STEP, MASS_SCALING, GRAVITY_POTENTIAL (1: the model has gravity, and
// ref_position is the reference positions; 0: ref_position is a placeholder, not read),
// WORK_ROWS_BY_GROUP.
__kernel void integrate(const uint n_nodes,
#if GATHER_IN_STEP
                        GATHER_ARGS,
#endif
                        __global real2* restrict position,
                        __global real2* restrict velocity,
                        __global real2* restrict node_force,
#if MASS_SCALING
                        __global const real2* restrict node_mass,
#else
                        __global const real* restrict node_mass,
#endif
                        __global const uint* restrict bc_group,
                        __global const real4* restrict bc_table,
                        const real gx, const real gy,
                        const real local_damping,
                        const real dt,
                        const real time_after,
                        const int step,
                        __global int* restrict conditions,
#if SKIN_TEST
                        __global const real2* restrict position_at_build,
                        __global uint* restrict monitor,
#if SKIN_OWNED
                        __global const uchar* restrict node_owned,
#endif
                        const uint slot,
                        const uint next_slot,
#endif
                        __global const real2* restrict ref_position,
                        const int account_work,
                        const int energy_row,
                        __global real2* restrict group_work,
                        __global real4* restrict group_row,
                        __global real2* restrict node_work,
                        const int node_rows,
                        __global real4* restrict node_energy,
                        __global real* restrict energy_partials) {
#if SKIN_TEST
  __local uint2 skin_scratch[GROUP_SIZE];
#endif
  __local real4 energy_scratch[GROUP_SIZE];
  const uint i = get_global_id(0), lid = get_local_id(0);
#if SKIN_TEST
  uint my_moved = 0u, my_speed = 0u;
#endif
  real4 work = (real4)(0, 0, 0, 0);  // (damping work, reaction work) this step; forward halves
  real4 row = (real4)(0, 0, 0, 0);   // (kinetic, gravity potential) on energy rows
  real4 terms = (real4)(0, 0, 0, 0);  // the node's terms of the row's ordered sums
  if (i < n_nodes) {
#if MASS_SCALING
    const real2 mass = node_mass[i];  // (true mass, inertia)
#else
    const real2 mass = (real2)(node_mass[i], node_mass[i]);
#endif
    const real2 v_before = velocity[i];
    real2 v = v_before;
#if GATHER_IN_STEP
    GATHER_PREFETCH(i, n_nodes);
    const real2 gathered = gathered_sum(i, GATHER_PASS);
#else
    const real2 gathered = node_force[i];
#endif
    const real2 f = gathered + mass.x * (real2)(gx, gy);
    node_force[i] = f;

    real2 fd = f;
    if (local_damping != (real)0) {
      // sign(0) = 0 in OpenCL, so a node at rest is not damped
      fd = f - local_damping * fabs(f) * sign(v);
    }
    v += fd / mass.y * dt;

#if WORK_ROWS_BY_GROUP
    const uint group_word = bc_group[i], group = group_word & 0xffu;
#else
    const uint group = bc_group[i];
#endif
    uint mask = 0u;
    if (group != 0) {
      const real4 bc = bc_table[group];
      mask = (uint)bc.x;
      const real ramp = bc.w > (real)0 ? fmin(time_after / bc.w, (real)1) : (real)1;
      if (mask & 1u) v.x = ramp * bc.y;
      if (mask & 2u) v.y = ramp * bc.z;
    }
    const real2 x_now = position[i];
    const real2 x = x_now + v * dt;
    if (account_work) {
      // Forces × the forward half step (v⁺ Δt/2) and the backward one (v⁻ Δt/2).
      const real2 damping = fd - f;
      const real2 reaction = mass.y * (v - v_before) / dt - f;
      const real2 fwd = (real)0.5 * dt * v, back = (real)0.5 * dt * v_before;
      const real2 on_damping = (real2)((mask & 1u) ? (real)0 : (real)1, (mask & 2u) ? (real)0 : (real)1);
      const real2 pd = on_damping * damping, pr = ((real2)(1, 1) - on_damping) * reaction;
      work.z = dot(pd, fwd);
      work.w = dot(pr, fwd);
      work.x = work.z + (step > 0 ? dot(pd, back) : (real)0);
      work.y = work.w + (step > 0 ? dot(pr, back) : (real)0);
#if WORK_ROWS_BY_GROUP
      if (group != 0) {
        const uint work_row = group_word >> 8;
        if (work.x != (real)0 || work.y != (real)0) node_work[work_row] += work.xy;
        if (energy_row) work.xy = node_work[work_row];
      } else if (energy_row) {
        work.xy = (real2)(0, 0);  // a free node's total: +0, as a row of its own would hold
      }
#else
      if (work.x != (real)0 || work.y != (real)0) node_work[i] += work.xy;
      if (energy_row) work.xy = node_work[i];  // the totals so far, for this row's sums
#endif
    }
    if (energy_row) {
      row.x = (real)0.5 * mass.y * dot(v_before, v);
#if GRAVITY_POTENTIAL
      row.y = -mass.x * dot((real2)(gx, gy), x_now - ref_position[i]);
#else
      row.y = (real)0;  // no gravity: ±0 per node, and the ordered sums of ±0 are +0
#endif
      // The node's own terms, summed in node order (rank-independent sums): (kinetic,
      // gravity potential, damping and reaction work up to t).
      terms = (real4)(row.x, row.y, work.x - work.z, work.y - work.w);
      if (node_rows) node_energy[i] = terms;
    }
    if (!(isfinite(x.x) && isfinite(x.y) && isfinite(v.x) && isfinite(v.y))) {
      atomic_min(&conditions[COND_BAD_NODE], (int)i);
      atomic_min(&conditions[COND_BAD_NODE_STEP], step);
    }
    velocity[i] = v;
    position[i] = x;
#if SKIN_TEST
    // NaN bits compare above +inf as uint: a NaN node forces a rebuild (and the run's NaN check stops it).
#if SKIN_OWNED
    if (node_owned[i] != 0) {  // a split run: ghosts' moves are their owners' to report
#else
    {
#endif
      my_moved = as_uint((float)length(x - position_at_build[i]));
      my_speed = as_uint((float)length(v));
    }
#endif
  }
  // Energy sums: the flags are the same for every work-item, so no barrier is skipped by some only.
  if (energy_row) {
    // The ordered block sums first: `terms` goes to local memory right after the region
    // that computed it (PoCL 3 lost a private value kept across several barriers here:
    // every work-item stored the group's last one).
    energy_scratch[lid] = terms;
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid % ORDERED_BLOCK == 0 && i < n_nodes) {
      const uint count = min((uint)ORDERED_BLOCK, n_nodes - i);
      real4 sum = (real4)(0, 0, 0, 0);
      for (uint k = 0; k < count; ++k) sum += energy_scratch[lid + k];
      vstore4(sum, i / ORDERED_BLOCK, energy_partials);
    }
    barrier(CLK_LOCAL_MEM_FENCE);  // the blocks are summed before the scratch is reused
    const uint g = get_group_id(0);
    const real4 w = group_sum4(energy_scratch, work);
    if (lid == 0 && account_work) group_work[g] = w.xy;
    barrier(CLK_LOCAL_MEM_FENCE);  // work-item 0 has read the last sum
    const real4 r = group_sum4(energy_scratch, row);
    if (lid == 0) group_row[g] = (real4)(r.x, r.y, w.z, w.w);
  }
#if SKIN_TEST
  if (i == 0) {
    monitor[RING_WORDS * next_slot + RING_MOVED] = 0u;
    monitor[RING_WORDS * next_slot + RING_SPEED] = 0u;
    monitor[RING_WORDS * next_slot + RING_JOINED] = 0u;
  }
  const uint2 largest = group_max_uint2(skin_scratch, (uint2)(my_moved, my_speed));
  if (lid == 0) {
    atomic_max(&monitor[RING_WORDS * slot + RING_MOVED], largest.x);
    atomic_max(&monitor[RING_WORDS * slot + RING_SPEED], largest.y);
  }
#endif
}
