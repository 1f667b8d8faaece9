// Edge tractions and pressures. One work-item per loaded boundary edge (a, b), ordered
// so that the body lies on its left (its outward normal is (e.y, -e.x)/|e|, e = b - a).
// Traction: a dead load per reference length, f = τ L₀ t. Pressure: a follower load
// normal to the current edge, f = -p n L t (positive p pushes into the body).
// Both ramp linearly from 0 over the load's rise time. Half of f goes to each node,
// written to the edge's two slots (the node gather sums them).
// load_table per load: (τx, τy, p, rise).
__kernel void boundary_loads(const uint n_edges,
                             __global const uint2* restrict edge_nodes,
                             __global const uint* restrict edge_load,
                             __global const real4* restrict load_table,
                             __global const real2* restrict ref_position,
                             __global const real2* restrict position,
                             const real thickness,
                             const real time,
                             __global real2* restrict edge_force) {
  const uint e = get_global_id(0);
  if (e >= n_edges) return;
  const uint2 ab = edge_nodes[e];
  const real4 load = load_table[edge_load[e]];
  const real ramp = load.w > (real)0 ? fmin(time / load.w, (real)1) : (real)1;
  const real2 e0 = ref_position[ab.y] - ref_position[ab.x];
  const real2 ec = position[ab.y] - position[ab.x];
  // -p n L = -p (ec.y, -ec.x)
  const real2 f = ramp * thickness * ((real2)(load.x, load.y) * length(e0) - load.z * (real2)(ec.y, -ec.x));
  edge_force[2 * e] = (real)0.5 * f;
  edge_force[2 * e + 1] = (real)0.5 * f;
}
