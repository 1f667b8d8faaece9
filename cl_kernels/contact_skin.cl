// Skin rebuild test, read back a few steps late so that the host never waits for the
// device inside the step loop. A ring of SKIN_SLOTS slots of four uints lives on the
// device: (largest move since the last detection, largest speed, a triangle joined the
// candidates, unused); the host reads slot k asynchronously at the step that wrote it
// and looks at it SKIN_SLOTS − 1 steps later.
//
// One work-item per node: how far the node moved since the last contact detection and
// how fast it goes now. The work-group takes the largest of each (in local memory) and
// its first work-item folds them into the slot with integer atomic_max on the bits of
// non-negative floats (their order as uint is the order of the values), so the result
// does not depend on scheduling. Global work-item 0 also clears the next slot, which the
// host read (in queue order) before this launch.
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).
__kernel void max_displacement(const uint n_nodes,
                               __global const real2* restrict position,
                               __global const real2* restrict velocity,
                               __global const real2* restrict position_at_build,
                               __global uint* restrict monitor,
                               const uint slot,
                               const uint next_slot) {
  __local uint moved[GROUP_SIZE], speed[GROUP_SIZE];
  const uint i = get_global_id(0), lid = get_local_id(0);
  if (i == 0) {
    monitor[4 * next_slot] = 0u;
    monitor[4 * next_slot + 1] = 0u;
    monitor[4 * next_slot + 2] = 0u;
  }
  // NaN bits compare above +inf as uint: a NaN node forces a rebuild (and the run's NaN check stops it).
  moved[lid] = i < n_nodes ? as_uint((float)length(position[i] - position_at_build[i])) : 0u;
  speed[lid] = i < n_nodes ? as_uint((float)length(velocity[i])) : 0u;
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
