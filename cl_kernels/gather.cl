// Node gather. One work-item per node: the sum of the values that elements, loaded
// edges and cohesive elements wrote into their slots for this node, read through CSR
// maps (node → corner slots, node → edge-end slots, node → CE4 slots) in the map's
// fixed order. Because the
// order never depends on scheduling, the sum is bitwise the same on every run; this is
// how fdem-cl avoids floating-point atomics. Contact forces arrive as 64-bit fixed point
// (summed with integer atomics, also order-independent) and are added last.
__kernel void gather_node_sums(const uint n_nodes,
                               __global const uint* restrict corner_start,
                               __global const uint* restrict corner_slot,
                               __global const real2* restrict corner_value,
                               const int use_edges,
                               __global const uint* restrict edge_start,
                               __global const uint* restrict edge_slot,
                               __global const real2* restrict edge_value,
                               const int use_ce4,
                               __global const uint* restrict ce4_start,
                               __global const uint* restrict ce4_slot,
                               __global const real2* restrict ce4_value,
                               const int use_contact,
                               __global const long* restrict contact_acc,
                               const real contact_unit,
                               __global real2* restrict node_sum) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  real2 sum = (real2)(0, 0);
  for (uint k = corner_start[i]; k < corner_start[i + 1]; ++k) sum += corner_value[corner_slot[k]];
  if (use_edges)
    for (uint k = edge_start[i]; k < edge_start[i + 1]; ++k) sum += edge_value[edge_slot[k]];
  if (use_ce4)
    for (uint k = ce4_start[i]; k < ce4_start[i + 1]; ++k) sum += ce4_value[ce4_slot[k]];
  if (use_contact) sum += contact_unit * (real2)((real)contact_acc[2 * i], (real)contact_acc[2 * i + 1]);
  node_sum[i] = sum;
}
