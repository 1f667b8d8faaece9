// Skin rebuild test. One work-item per node: how far the node moved since the last
// contact detection; the largest distance over all nodes is kept with an integer
// atomic_max on the bits of a non-negative float (their order as uint is the order of
// the values), so the result does not depend on scheduling.
__kernel void max_displacement(const uint n_nodes,
                               __global const real2* restrict position,
                               __global const real2* restrict position_at_build,
                               __global uint* restrict result) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  const float moved = (float)length(position[i] - position_at_build[i]);
  atomic_max(result, as_uint(moved));
}
