// Central-difference step. One work-item per node:
//   f   = Σ element and load forces + m g               (gravity uses the true mass)
//   f_d = f - α |f| sgn(v), per component               (Cundall local damping, Eq. 18)
//   v  += f_d / m_inertia · Δt                           (m_inertia scaled or true)
//   prescribed components of v overwrite it (ramped over their rise time)
//   x  += v Δt
// node_force is overwritten with f, the node's out-of-balance force, which the host
// reads for history (max unbalanced force, reactions on constrained regions).
// bc_table per group: (mask, vx, vy, rise); mask bit 0 = x prescribed, bit 1 = y.
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
                        __global int* restrict conditions) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
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
}
