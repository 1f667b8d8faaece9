// Skin rebuild test, read back a few steps late so that the host never waits for the
// device inside the step loop. A ring of SKIN_SLOTS slots of four uints lives on the
// device: (largest move since the last detection, largest speed, a triangle joined the
// candidates, unused); the host reads slot k asynchronously at the step that wrote it
// and looks at it SKIN_SLOTS − 1 steps later.
//
// One work-item per node: how far the node moved since the last contact detection and
// how fast it goes now; the largest of each over all nodes is kept with integer
// atomic_max on the bits of non-negative floats (their order as uint is the order of
// the values), so the result does not depend on scheduling. Work-item 0 also clears the
// next slot, which the host read (in queue order) before this launch.
__kernel void max_displacement(const uint n_nodes,
                               __global const real2* restrict position,
                               __global const real2* restrict velocity,
                               __global const real2* restrict position_at_build,
                               __global uint* restrict monitor,
                               const uint slot,
                               const uint next_slot) {
  const uint i = get_global_id(0);
  if (i == 0) {
    monitor[4 * next_slot] = 0u;
    monitor[4 * next_slot + 1] = 0u;
    monitor[4 * next_slot + 2] = 0u;
  }
  if (i >= n_nodes) return;
  const float moved = (float)length(position[i] - position_at_build[i]);
  const float speed = (float)length(velocity[i]);
  // NaN bits compare above +inf as uint: a NaN node forces a rebuild (and the run's NaN check stops it).
  atomic_max(&monitor[4 * slot], as_uint(moved));
  atomic_max(&monitor[4 * slot + 1], as_uint(speed));
}
