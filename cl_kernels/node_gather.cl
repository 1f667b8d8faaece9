// Node gather. One work-item per node: the sum of the values that elements, loaded
// edges and cohesive elements wrote into their slots for this node, read through CSR
// maps (node → corner slots, node → edge-end slots, node → CE4 slots) in the map's
// fixed order. Because the order never depends on scheduling, the sum is bitwise the
// same on every run; this is how fdem-cl avoids floating-point atomics. Contact forces
// arrive as 64-bit fixed point (summed with integer atomics, also order-independent)
// and are added last.
// Defines from the host (NodeGather), each 0 or 1: GATHER_EDGES (loaded edges),
// GATHER_CE4 (cohesive elements), GATHER_CONTACT (contact); absent parts have no
// arguments.
__kernel void gather_node_sums(const uint n_nodes,
                               __global const uint* restrict corner_start,
                               __global const uint* restrict corner_slot,
                               __global const real2* restrict corner_value,
#if GATHER_EDGES
                               __global const uint* restrict edge_start,
                               __global const uint* restrict edge_slot,
                               __global const real2* restrict edge_value,
#endif
#if GATHER_CE4
                               __global const uint* restrict ce4_start,
                               __global const uint* restrict ce4_slot,
                               __global const real2* restrict ce4_value,
#endif
#if GATHER_CONTACT
                               __global const long* restrict contact_acc,
                               const real contact_unit,
#endif
                               __global real2* restrict node_sum) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  real2 sum = (real2)(0, 0);
  for (uint k = corner_start[i]; k < corner_start[i + 1]; ++k) sum += corner_value[corner_slot[k]];
#if GATHER_EDGES
  for (uint k = edge_start[i]; k < edge_start[i + 1]; ++k) sum += edge_value[edge_slot[k]];
#endif
#if GATHER_CE4
  for (uint k = ce4_start[i]; k < ce4_start[i + 1]; ++k) sum += ce4_value[ce4_slot[k]];
#endif
#if GATHER_CONTACT
  sum += contact_unit * (real2)((real)contact_acc[2 * i], (real)contact_acc[2 * i + 1]);
#endif
  node_sum[i] = sum;
}
