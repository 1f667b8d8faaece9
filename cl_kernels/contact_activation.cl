// Contact activation "fractured". One work-item per CE4: once it has broken, the two
// triangles it joined become contact candidates (their new faces are free surfaces);
// `changed` is set when a triangle joins, so the host knows to run a new detection.
// Every writer writes the same value, so the result does not depend on the order.
__kernel void activate_broken(const uint n_ce4,
                              __global const int2* restrict status,
                              __global const uint2* restrict ce4_triangles,
                              __global uint* restrict active,
                              __global uint* restrict changed) {
  const uint e = get_global_id(0);
  if (e >= n_ce4 || status[e].x == 0) return;
  const uint2 t = ce4_triangles[e];
  if (active[t.x] == 0u || active[t.y] == 0u) {
    active[t.x] = 1u;
    active[t.y] = 1u;
    *changed = 1u;
  }
}
