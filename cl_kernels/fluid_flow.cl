// Fluid in the cracks (engine/stages/fluid_flow.*; docs/case-format.md "[fluid]").
// The network: every CE4 is a segment between two network vertices (the mesh vertices
// at its ends i = i' and j = j'; every split copy of a vertex is the same vertex) and
// carries fluid while it is broken (CohesiveForces status.x >= 1; CE4s on [fluid] crack
// start broken) or, with DAMAGED_SEGMENTS (fluid.segments = "damaged", the default),
// from the step one of its Gauss points has softened (D_max > 0: past the peak of its
// law), so the fluid fills and loads the cohesive zone ahead of the broken crack as well.
// Per step, in order, on the positions the other force stages use:
//   fluid_segments  one work-item per CE4: end openings o = (x' - x).n (n the right normal
//                   of the chord, as cohesive_forces.cl), apertures w = max(o, 0) + w_r, the
//                   volume of each half (lumped: h t (3 w_a + w_b) / 8 to the i end), the
//                   cubic-law conductance w_m³ t / (12 μ h) with w_m = (w_a + w_b) / 2; a
//                   segment wider than w_max flags itself (the stable step assumed it).
//   fluid_vertices  one work-item per vertex: its volume V (the halves at it, CSR order),
//                   the work of the pressure on the faces ½ (p + p') (V' - V), new p;
//                   (V₀, p) also into the `front` copy the sub-steps' neighbours read.
//   n_sub × fluid_substep per vertex: V₀ += Δt_s Σ q (CSR order), q = c (p_a - p_b)
//                   from the front copy, the energy that took out of the vertex (the
//                   viscous dissipation), then the source; (V₀, p) into the `back` copy
//                   (the two copies swap each sub-step). (LEAK_OFF: a segment's exposure
//                   time is stamped, Carter's leak-off taken out of V₀ before the source)
//   fluid_forces    one work-item per CE4: the pressures on the two faces into four slots
//                   (i, j, j', i'), the same slots the CE4 stage has, which the node
//                   gather adds through the CE4 map (GATHER_FLUID in node_gather.cl).
// The fluid at a vertex is V₀, its volume at zero pressure; the state law is
// p = K_f max(V₀/V - 1, 0) (a vertex with less fluid than room is at p = 0). Its stored
// energy is U = K_f V ((1 + d) ln(1 + d) - d), d = V₀/V - 1 > 0 (∂U/∂V = -p), and fluid
// entering at a vertex brings H = ∂U/∂V₀ = K_f ln(1 + d) per unit V₀, so the flow from a
// to b dissipates about q (H_a - H_b) >= 0 (counted exactly as the energy the sub-step's
// fluxes took out of the vertices). The injection work is ∫ H dV₀, the source's V₀ times
// H at the pressure it enters at (a held pressure: that pressure): ∫ p Q dt while p << K_f
// (H = p (1 - p/2K_f + ...); with p = 0.3 K_f the difference was 13%, in a test). The
// faces' work is Σ p ΔV with the pressure their forces had over the step; lumped
// half-volumes and the forces of the same halves make it the forces' work to first order.
// No floating-point atomics: every sum is over a CSR list in fixed order.

inline real fluid_excess(const real v0, const real v) { return v > (real)0 ? fmax(v0 / v - (real)1, (real)0) : (real)0; }
inline real fluid_stored(const real bulk, const real v, const real d) {
  return bulk * v * (((real)1 + d) * log1p(d) - d);
}

__kernel void fluid_segments(const uint n_ce4,
                             __global const uint4* restrict ce4_nodes,
                             __global const real2* restrict position,
                             __global const int2* restrict status,
#if DAMAGED_SEGMENTS
                             __global const real4* restrict gp_state,
#endif
                             __global const real* restrict seg_h,
                             const real thickness,
                             const real residual,
                             const real max_aperture,
                             const real viscosity,
                             const int step,
                             __global real4* restrict seg_geom,
                             __global int* restrict too_wide,
                             __global uint* restrict wet_count) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  if (e == 0) wet_count[0] = 0;  // fluid_vertices, next in the queue, lists the wet vertices anew
#if DAMAGED_SEGMENTS
  // An intact CE4 carries fluid once softened: D_max > 0 at one of its three points
  // (irreversible, so a segment never closes to the network again).
  const bool carries = status[e].x >= 1 || gp_state[3 * e].x > (real)0 || gp_state[3 * e + 1].x > (real)0 ||
                       gp_state[3 * e + 2].x > (real)0;
#else
  const bool carries = status[e].x >= 1;
#endif
  if (!carries) {
    seg_geom[e] = (real4)(0, 0, 0, 0);
    return;
  }
  const uint4 nd = ce4_nodes[e];
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  const real2 chord = (xj - xi) + (xj2 - xi2);
  const real2 t = chord / length(chord);
  const real2 n = (real2)(t.y, -t.x);
  const real wa = fmax(dot(xi2 - xi, n), (real)0) + residual;
  const real wb = fmax(dot(xj2 - xj, n), (real)0) + residual;
  const real h = seg_h[e];
  const real wm = (real)0.5 * (wa + wb);
  const real c = wm * wm * wm * thickness / ((real)12 * viscosity * h);
  seg_geom[e] = (real4)(h * thickness * ((real)3 * wa + wb) / (real)8, h * thickness * (wa + (real)3 * wb) / (real)8, c, wm);
  if (fmax(wa, wb) > max_aperture) {
    atomic_min(&too_wide[0], (int)e);
    atomic_min(&too_wide[1], step);
  }
}

// vertex_state: (V₀ [m³], V [m³], p [Pa], U [J]); vertex_energy: (injection work [J],
// work of the pressure on the faces [J], injected V₀ [m³], viscous dissipation [J]),
// cumulative.
__kernel void fluid_vertices(const uint n_vertices,
                             __global const uint* restrict vertex_start,
                             __global const uint* restrict vertex_end,
                             __global const real4* restrict seg_geom,
                             const real bulk,
                             __global const uchar* restrict source,
#if LEAK_OFF
                             __global const real* restrict seg_exposed,
#endif
                             __global real4* restrict vertex_state,
                             __global real4* restrict vertex_energy,
                             __global real2* restrict front,
                             __global uint* restrict wet_count,
                             __global uint* restrict wet) {
  const uint v = get_global_id(0);
  if (v >= n_vertices) return;
  real volume = 0;
  bool flows = source[v] != 0;  // a sub-step can change this vertex: list it
  for (uint k = vertex_start[v]; k < vertex_start[v + 1]; ++k) {
    const uint end = vertex_end[k];
    const real4 g = seg_geom[end >> 1];
    volume += (end & 1u) ? g.y : g.x;
    flows = flows || g.z != (real)0;
#if LEAK_OFF
    flows = flows || seg_exposed[end >> 1] >= (real)0;
#endif
  }
  // The list's order depends on the atomics, its content does not, and each listed
  // vertex's sub-step reads only the copies: the results do not depend on the order.
  if (flows) wet[atomic_inc(wet_count)] = v;
  real4 s = vertex_state[v];
  const real d = fluid_excess(s.x, volume);
  const real p = bulk * d;
  if (volume != s.y) {
    real4 en = vertex_energy[v];
    en.y += s.z * (volume - s.y);  // the pressure the faces' forces had over the last step
    vertex_energy[v] = en;
  }
  vertex_state[v] = (real4)(s.x, volume, p, fluid_stored(bulk, volume, d));
  front[v] = (real2)(s.x, p);  // what the first sub-step's neighbours read
}

// One sub-step of the flow, one work-item per wet vertex (the list fluid_vertices made:
// a vertex with no open or exposed segment and no source has nothing to do): the net inflow from the fluxes
// q = c (p_a - p_b) of its segments (CSR order), taken from the pressures and fluid of the
// sub-step's start in `front` ((V₀, p) per vertex, read for the neighbours), the new V₀, p
// and U in vertex_state (its own, in place) and (V₀, p) into `back` for the next sub-step.
// Each segment's flux is computed at both its ends with the same operands, so what leaves
// one vertex is exactly what enters the other; one launch a sub-step instead of a flux and
// a balance launch (the fluid's cost is mostly launches: issue 32's fluid row).
// source: per vertex 1 where the fluid enters. With PRESSURE_SOURCE the source vertices
// are held at `source_value` [Pa]; else each takes source_value [m³/s] of V₀.
__kernel void fluid_substep(__global const uint* restrict wet_count,
                            __global const uint* restrict wet,
                            __global const uint* restrict vertex_start,
                            __global const uint* restrict vertex_end,
                            __global const uint2* restrict seg_vertex,
                            __global const real4* restrict seg_geom,
                            __global const real2* restrict front,
                            __global const uchar* restrict source,
                            const real source_value,
                            const real bulk,
                            const real dt_sub,
#if LEAK_OFF
                            const real t_sub,
                            const real leak_off,
                            const real thickness,
                            __global const real* restrict seg_h,
                            __global real* restrict seg_exposed,
                            __global real2* restrict vertex_leak,
#endif
                            __global real4* restrict vertex_state,
                            __global real4* restrict vertex_energy,
                            __global real2* restrict back) {
  const uint i = get_global_id(0);
  if (i >= wet_count[0]) return;
  const uint v = wet[i];
  real inflow = 0;
#if LEAK_OFF
  // Carter: each exposed segment loses 2 C_L / √(t - t_e) per unit of its area h t (both
  // faces), half of it at each end; over the sub-step [t, t + Δt_s] exactly
  // 2 C_L (h t / 2) · 2 (√(t + Δt_s - t_e) - √(t - t_e)) at this end. A segment's
  // exposure time is the start of the first sub-step in which it is open with fluid at
  // one of its ends (-1 until then; never reset): both ends find the same time from the
  // same operands, and the segment's first end records it.
  real leak = 0;
#endif
  for (uint k = vertex_start[v]; k < vertex_start[v + 1]; ++k) {
    const uint end = vertex_end[k];
    const uint e = end >> 1;
    const real c = seg_geom[e].z;
#if LEAK_OFF
    real te = seg_exposed[e];
#endif
    if (c != (real)0) {  // closed: no flow, no new exposure
      const uint2 ab = seg_vertex[e];
      const real2 fa = front[ab.x], fb = front[ab.y];
      const real q = c * (fa.y - fb.y);
      inflow += (end & 1u) ? q : -q;
#if LEAK_OFF
      if (te < (real)0 && (fa.x > (real)0 || fb.x > (real)0)) {
        te = t_sub;
        if (!(end & 1u)) seg_exposed[e] = te;
      }
#endif
    }
#if LEAK_OFF
    if (te >= (real)0) leak += seg_h[e] * (sqrt(t_sub + dt_sub - te) - sqrt(t_sub - te));
#endif
  }
  real4 s = vertex_state[v];
#if LEAK_OFF
  leak *= (real)2 * leak_off * thickness;
  if (inflow == (real)0 && !source[v] && leak == (real)0) {
    back[v] = (real2)(s.x, s.z);
    return;
  }
#else
  if (inflow == (real)0 && !source[v]) {
    back[v] = (real2)(s.x, s.z);
    return;
  }
#endif
  s.x += dt_sub * inflow;
  // The flow's loss at this vertex: its energy before less after the fluxes (the sum over
  // the vertices is the viscous dissipation of the sub-step, exactly as the explicit
  // update has it; Σ q (H_a - H_b) Δt_s over-counts it by the update's O(Δt_s²) term).
  const real u_flowed = fluid_stored(bulk, s.y, fluid_excess(s.x, s.y));
  real4 en = vertex_energy[v];
  en.w += s.w - u_flowed;
#if LEAK_OFF
  // The leak takes what the vertex holds at most; the fluid that leaves takes its energy
  // with it, a term of its own in the account: the stored energy before less after, and
  // at a vertex held at p_s, which refills what leaked at p_s, H(p_s) per unit V₀ (a
  // leak larger than the fluid's compressed excess V p / K_f empties the spring in one
  // sub-step, so the stored energy would miss the p ΔV₀ the refill is charged).
  leak = fmin(leak, fmax(s.x, (real)0));
  if (leak > (real)0) {
    s.x -= leak;
    real2 l = vertex_leak[v];
    l.x += leak;
#if PRESSURE_SOURCE
    if (source[v]) l.y += bulk * log1p(source_value / bulk) * leak;
    else l.y += u_flowed - fluid_stored(bulk, s.y, fluid_excess(s.x, s.y));
#else
    l.y += u_flowed - fluid_stored(bulk, s.y, fluid_excess(s.x, s.y));
#endif
    vertex_leak[v] = l;
  }
#endif
  if (source[v] && s.y > (real)0) {
#if PRESSURE_SOURCE
    // Held at p_s: the source fills the vertex to V (1 + p_s / K_f) and works at p_s.
    const real added = s.y * ((real)1 + source_value / bulk) - s.x;
    const real h_work = bulk * log1p(source_value / bulk);
#else
    const real added = dt_sub * source_value;
    const real h_work = bulk * log1p(fluid_excess(s.x + (real)0.5 * added, s.y));  // at the sub-step's middle
#endif
    s.x += added;
    en.x += h_work * added;
    en.z += added;
  }
  vertex_energy[v] = en;
  const real d = fluid_excess(s.x, s.y);
  s.z = bulk * d;
  s.w = fluid_stored(bulk, s.y, d);
  vertex_state[v] = s;
  back[v] = (real2)(s.x, s.z);
}

__kernel void fluid_forces(const uint n_ce4,
                           __global const uint4* restrict ce4_nodes,
                           __global const real2* restrict position,
                           __global const uint2* restrict seg_vertex,
                           __global const real4* restrict seg_geom,
                           __global const real* restrict seg_h,
                           __global const real4* restrict vertex_state,
                           const real thickness,
                           __global real2* restrict fluid_slots) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  if (seg_geom[e].z == (real)0) {
    const real2 zero = (real2)(0, 0);
    fluid_slots[4 * e] = zero, fluid_slots[4 * e + 1] = zero, fluid_slots[4 * e + 2] = zero, fluid_slots[4 * e + 3] = zero;
    return;
  }
  const uint4 nd = ce4_nodes[e];
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  const real2 chord = (xj - xi) + (xj2 - xi2);
  const real2 t = chord / length(chord);
  const real2 n = (real2)(t.y, -t.x);
  const uint2 ab = seg_vertex[e];
  const real pa = vertex_state[ab.x].z, pb = vertex_state[ab.y].z;
  const real ht = seg_h[e] * thickness / (real)8;
  const real2 fa = ht * ((real)3 * pa + pb) * n, fb = ht * (pa + (real)3 * pb) * n;
  fluid_slots[4 * e] = -fa;      // i: face 1 pushed away from face 2
  fluid_slots[4 * e + 1] = -fb;  // j
  fluid_slots[4 * e + 2] = fb;   // j'
  fluid_slots[4 * e + 3] = fa;   // i'
}
