// Node gather. One work-item per node: the sum of the values that elements, loaded
// edges and cohesive elements wrote into their slots for this node, read through one CSR
// map (node_start, node_slot): a node's entries are its corner slots, then its
// loaded-edge-end slots, then its CE4 slots, each in slot order, and an entry is
// (part << 30) | slot with part 0 corner, 1 edge, 2 CE4 (DeviceArrays::node_slot; one
// start array instead of three, 24 B/TRI3). Because the order never depends on
// scheduling, the sum is bitwise the same on every run; this is how fdem-cl avoids
// floating-point atomics. Contact forces arrive as 64-bit fixed point (summed with
// integer atomics, also order-independent) and are added last.
// Defines from the host (NodeGather, and Integrate when it gathers the forces itself),
// each 0 or 1: GATHER_EDGES (loaded edges), GATHER_CE4 (cohesive elements),
// GATHER_CONTACT (contact), GATHER_FLUID ([fluid]: the fluid stage's four slots per CE4,
// read through the CE4 entries after the CE4's own, at the nodes whose flag in
// fluid_loaded_node is set: a CE4 whose fluid forces were never written holds the +0s it
// was made with, and a sum that starts at +0 is never -0, so adding them changes no bit;
// the flag, set by the fluid stage's forces before the gather, spares a dry node's
// reads); absent parts have no arguments, and their entries are passed over.

#define GATHER_PART(entry) ((entry) >> 30)
#define GATHER_SLOT(entry) ((entry) & 0x3fffffffu)

// The slot arrays as kernel parameters (GATHER_ARGS) and as the arguments of
// gathered_sum (GATHER_PASS), for the parts the defines switch on.
#if GATHER_EDGES
#define GATHER_EDGE_ARGS , __global const real2 *restrict edge_value
#define GATHER_EDGE_PASS , edge_value
#else
#define GATHER_EDGE_ARGS
#define GATHER_EDGE_PASS
#endif
#if GATHER_CE4
#if GATHER_FLUID
#define GATHER_CE4_ARGS                                                                            \
  , __global const real2 *restrict ce4_value, __global const real2 *restrict fluid_value,          \
      __global const uchar *restrict fluid_loaded_node
#define GATHER_CE4_PASS , ce4_value, fluid_value, fluid_loaded_node
#else
#define GATHER_CE4_ARGS , __global const real2 *restrict ce4_value
#define GATHER_CE4_PASS , ce4_value
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
  __global const uint *restrict node_start, __global const uint *restrict node_slot,              \
      __global const real2 *restrict corner_value GATHER_EDGE_ARGS GATHER_CE4_ARGS GATHER_CONTACT_ARGS
#define GATHER_PASS node_start, node_slot, corner_value GATHER_EDGE_PASS GATHER_CE4_PASS GATHER_CONTACT_PASS

// Node i's sum, parts in a fixed order: corners, loaded edges, CE4s, contact.
inline real2 gathered_sum(const uint i, GATHER_ARGS) {
  real2 sum = (real2)(0, 0);
  const uint last = node_start[i + 1];
  uint k = node_start[i];
  for (; k < last && GATHER_PART(node_slot[k]) == 0u; ++k) sum += corner_value[GATHER_SLOT(node_slot[k])];
#if GATHER_EDGES
  for (; k < last && GATHER_PART(node_slot[k]) == 1u; ++k) sum += edge_value[GATHER_SLOT(node_slot[k])];
#else
  while (k < last && GATHER_PART(node_slot[k]) == 1u) ++k;
#endif
#if GATHER_CE4
  const uint ce4_first = k;
  for (; k < last; ++k) sum += ce4_value[GATHER_SLOT(node_slot[k])];  // the rest are CE4 entries
#if GATHER_FLUID
  if (fluid_loaded_node[i] != 0)
    for (uint q = ce4_first; q < last; ++q) sum += fluid_value[GATHER_SLOT(node_slot[q])];
#endif
#endif
#if GATHER_CONTACT
  sum += contact_unit * (real2)((real)contact_acc[2 * i], (real)contact_acc[2 * i + 1]);
#endif
  return sum;
}

// CPU devices (FDEM_CPU_PREFETCH, set by the host where the device is not a GPU): PoCL runs
// a group's work-items one after the other, and a node's CE4 slots lie where their CE4s
// are numbered, not near the node, so each slot read waits on memory. Node i asks for the
// CE4 slots of node i + GATHER_AHEAD while it sums its own. No value changes.
#define GATHER_AHEAD 32u
#if defined(FDEM_CPU_PREFETCH) && GATHER_CE4
#define GATHER_PREFETCH(i, n_nodes)                                                                \
  if ((i) + GATHER_AHEAD < (n_nodes)) {                                                            \
    const uint ahead_last = node_start[(i) + GATHER_AHEAD + 1u];                                   \
    for (uint ahead = node_start[(i) + GATHER_AHEAD]; ahead < ahead_last; ++ahead)                 \
      if (GATHER_PART(node_slot[ahead]) == 2u) __builtin_prefetch(ce4_value + GATHER_SLOT(node_slot[ahead])); \
  }
#else
#define GATHER_PREFETCH(i, n_nodes)
#endif

// One work-item per node: node_sum[i] = gathered_sum(i).
__kernel void gather_node_sums(const uint n_nodes, GATHER_ARGS, __global real2* restrict node_sum) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  GATHER_PREFETCH(i, n_nodes);
  node_sum[i] = gathered_sum(i, GATHER_PASS);
}
