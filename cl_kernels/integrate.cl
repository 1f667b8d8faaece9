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
// With a contact skin (skin_monitor != 0) the step also takes the skin test of the next
// step's contact stage (engine/stages/contact_skin.hpp explains the ring): the node's move since the
// last detection and its speed, the work-group's largest of each folded into slot
// `slot` with integer atomic_max on float bits, and global work-item 0 clears slot
// `next_slot`. Doing it here saves a launch and a pass over the nodes.
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).
__kernel void integrate(const uint n_nodes,
                        __global real2* restrict position,
                        __global real2* restrict velocity,
                        __global real2* restrict node_force,
                        __global const real2* restrict node_mass,
                        __global const uint* restrict bc_group,
                        __global const real4* restrict bc_table,
                        const real gx, const real gy,
                        const real local_damping,
                        const real dt,
                        const real time_after,
                        const int step,
                        __global int* restrict conditions,
                        const int skin_monitor,
                        __global const real2* restrict position_at_build,
                        __global uint* restrict monitor,
                        const uint slot,
                        const uint next_slot) {
  __local uint moved[GROUP_SIZE], speed[GROUP_SIZE];
  const uint i = get_global_id(0), lid = get_local_id(0);
  uint my_moved = 0u, my_speed = 0u;
  if (i < n_nodes) {
    const real2 mass = node_mass[i];  // (true mass, inertia)
    real2 v = velocity[i];
    const real2 f = node_force[i] + mass.x * (real2)(gx, gy);
    node_force[i] = f;

    real2 fd = f;
    if (local_damping != (real)0) {
      // sign(0) = 0 in OpenCL, so a node at rest is not damped
      fd = f - local_damping * fabs(f) * sign(v);
    }
    v += fd / mass.y * dt;

    const uint group = bc_group[i];
    if (group != 0) {
      const real4 bc = bc_table[group];
      const uint mask = (uint)bc.x;
      const real ramp = bc.w > (real)0 ? fmin(time_after / bc.w, (real)1) : (real)1;
      if (mask & 1u) v.x = ramp * bc.y;
      if (mask & 2u) v.y = ramp * bc.z;
    }
    const real2 x = position[i] + v * dt;
    if (!(isfinite(x.x) && isfinite(x.y) && isfinite(v.x) && isfinite(v.y))) {
      atomic_min(&conditions[COND_BAD_NODE], (int)i);
      atomic_min(&conditions[COND_BAD_NODE_STEP], step);
    }
    velocity[i] = v;
    position[i] = x;
    if (skin_monitor) {
      // NaN bits compare above +inf as uint: a NaN node forces a rebuild (and the run's NaN check stops it).
      my_moved = as_uint((float)length(x - position_at_build[i]));
      my_speed = as_uint((float)length(v));
    }
  }
  if (!skin_monitor) return;  // the same for every work-item: no barrier is skipped by some only
  if (i == 0) {
    monitor[4 * next_slot] = 0u;
    monitor[4 * next_slot + 1] = 0u;
    monitor[4 * next_slot + 2] = 0u;
  }
  moved[lid] = my_moved;
  speed[lid] = my_speed;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = GROUP_SIZE / 2; s > 0; s >>= 1) {
    if (lid < s) {
      moved[lid] = max(moved[lid], moved[lid + s]);
      speed[lid] = max(speed[lid], speed[lid + s]);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lid == 0) {
    atomic_max(&monitor[4 * slot], moved[0]);
    atomic_max(&monitor[4 * slot + 1], speed[0]);
  }
}
