// Node gather. One work-item per node: the sum of the values that elements, loaded
// edges and cohesive elements wrote into their slots for this node, read through CSR
// maps (node → corner slots, node → edge-end slots, node → CE4 slots) in the map's
// fixed order. Because the order never depends on scheduling, the sum is bitwise the
// same on every run; this is how fdem-cl avoids floating-point atomics. Contact forces
// arrive as 64-bit fixed point (summed with integer atomics, also order-independent)
// and are added last.
// Defines from the host (NodeGather, and Integrate when it gathers the forces itself),
// each 0 or 1: GATHER_EDGES (loaded edges), GATHER_CE4 (cohesive elements),
// GATHER_CONTACT (contact), GATHER_FLUID ([fluid]: the fluid stage's four slots per CE4,
// read through the CE4 map after the CE4's own); absent parts have no arguments.

// The maps and slot arrays as kernel parameters (GATHER_ARGS) and as the arguments of
// gathered_sum (GATHER_PASS), for the parts the defines switch on.
#if GATHER_EDGES
#define GATHER_EDGE_ARGS                                                                           \
  , __global const uint *restrict edge_start, __global const uint *restrict edge_slot,            \
      __global const real2 *restrict edge_value
#define GATHER_EDGE_PASS , edge_start, edge_slot, edge_value
#else
#define GATHER_EDGE_ARGS
#define GATHER_EDGE_PASS
#endif
#if GATHER_CE4
#define GATHER_CE4_ARGS                                                                            \
  , __global const uint *restrict ce4_start, __global const uint *restrict ce4_slot,              \
      __global const real2 *restrict ce4_value
#define GATHER_CE4_PASS , ce4_start, ce4_slot, ce4_value
#if GATHER_FLUID
#undef GATHER_CE4_ARGS
#undef GATHER_CE4_PASS
#define GATHER_CE4_ARGS                                                                            \
  , __global const uint *restrict ce4_start, __global const uint *restrict ce4_slot,              \
      __global const real2 *restrict ce4_value, __global const real2 *restrict fluid_value
#define GATHER_CE4_PASS , ce4_start, ce4_slot, ce4_value, fluid_value
#endif
#else
#define GATHER_CE4_ARGS
#define GATHER_CE4_PASS
#endif
#if GATHER_CONTACT
#define GATHER_CONTACT_ARGS , __global const long *restrict contact_acc, const real contact_unit
#define GATHER_CONTACT_PASS , contact_acc, contact_unit
#else
#define GATHER_CONTACT_ARGS
#define GATHER_CONTACT_PASS
#endif
#define GATHER_ARGS                                                                                \
  __global const uint *restrict corner_start, __global const uint *restrict corner_slot,          \
      __global const real2 *restrict corner_value GATHER_EDGE_ARGS GATHER_CE4_ARGS GATHER_CONTACT_ARGS
#define GATHER_PASS corner_start, corner_slot, corner_value GATHER_EDGE_PASS GATHER_CE4_PASS GATHER_CONTACT_PASS

// Node i's sum, parts in a fixed order: corners, loaded edges, CE4s, contact.
inline real2 gathered_sum(const uint i, GATHER_ARGS) {
  real2 sum = (real2)(0, 0);
  for (uint k = corner_start[i]; k < corner_start[i + 1]; ++k) sum += corner_value[corner_slot[k]];
#if GATHER_EDGES
  for (uint k = edge_start[i]; k < edge_start[i + 1]; ++k) sum += edge_value[edge_slot[k]];
#endif
#if GATHER_CE4
  for (uint k = ce4_start[i]; k < ce4_start[i + 1]; ++k) sum += ce4_value[ce4_slot[k]];
#if GATHER_FLUID
  for (uint k = ce4_start[i]; k < ce4_start[i + 1]; ++k) sum += fluid_value[ce4_slot[k]];
#endif
#endif
#if GATHER_CONTACT
  sum += contact_unit * (real2)((real)contact_acc[2 * i], (real)contact_acc[2 * i + 1]);
#endif
  return sum;
}

// One work-item per node: node_sum[i] = gathered_sum(i).
__kernel void gather_node_sums(const uint n_nodes, GATHER_ARGS, __global real2* restrict node_sum) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  node_sum[i] = gathered_sum(i, GATHER_PASS);
}
