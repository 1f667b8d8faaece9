// Contact activation "fractured". One work-item per CE4: once it has broken, the two
// triangles it joined become contact candidates (their new faces are free surfaces).
// A joining triangle's mask entry becomes `stamp` (step + 2; 1 is "from the start"), so
// the contact stage can tell the couples it meets over an overlap because a triangle
// joined (contact_forces.cl) from those that approached.
// When a triangle joins, word RING_JOINED of this step's slot of the monitor ring
// (engine/stages/monitor_ring.hpp) is set, so the host runs a new detection when it reads that slot.
// Every writer writes the same value (the step's stamp), so the result does not depend on the order.
__kernel void activate_broken(const uint n_ce4,
                              __global const int2* restrict status,
                              __global const uint2* restrict ce4_triangles,
                              __global uint* restrict active,
                              __global uint* restrict monitor,
#ifdef OWNED_FLAG
                              __global const uchar* restrict ce4_owned,
#endif
                              const uint slot,
                              const uint stamp) {
  const uint e = get_global_id(0);
  if (e >= n_ce4 || status[e].x == 0) return;
  const uint2 t = ce4_triangles[e];
  if (active[t.x] == 0u || active[t.y] == 0u) {
    if (active[t.x] == 0u) active[t.x] = stamp;
    if (active[t.y] == 0u) active[t.y] = stamp;
#ifdef OWNED_FLAG
    // A split run: the flag is the owner's (see ContactActivation); the host takes the
    // largest over the ranks.
    if (ce4_owned[e] != 0)
#endif
    monitor[RING_WORDS * slot + RING_JOINED] = 1u;
  }
}
