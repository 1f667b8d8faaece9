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
//                   the work of the pressure on the faces p_mid (V' - V), new p, and
//                   V' - V into vertex_rate (the next step's mid-step prediction);
//                   (V₀, p) also into the `front` copy the sub-steps' neighbours read.
//   n_sub × fluid_substep per vertex: V₀ += Δt_s Σ q (CSR order), q = c (p_a - p_b)
//                   from the front copy, the energy that took out of the vertex (the
//                   viscous dissipation), then the source; (V₀, p) into the `back` copy
//                   (the two copies swap each sub-step). (LEAK_OFF: a segment's exposure
//                   time is stamped, Carter's leak-off taken out of V₀ before the source)
//   fluid_forces    one work-item per CE4: the pressures at the ends' mid-step rooms
//                   (mid_step_volume) on the two faces into four slots
//                   (i, j, j', i'), the same slots the CE4 stage has, which the node
//                   gather adds through the CE4 map (GATHER_FLUID in node_gather.cl)
//                   at the nodes it flags in fluid_loaded_node (one byte a node: the
//                   gather spares the dry nodes' reads of the fluid slots).
// The fluid at a vertex is V₀, its volume at zero pressure; the state law is
// p = K_f max(V₀/V - 1, 0) (a vertex with less fluid than room is at p = 0). Its stored
// energy is U = K_f V ((1 + d) ln(1 + d) - d), d = V₀/V - 1 > 0 (∂U/∂V = -p), and fluid
// entering at a vertex brings H = ∂U/∂V₀ = K_f ln(1 + d) per unit V₀, so the flow from a
// to b dissipates about q (H_a - H_b) >= 0 (counted exactly as the energy the sub-step's
// fluxes took out of the vertices). The injection work is ∫ H dV₀, the source's V₀ times
// H at the pressure it enters at (a held pressure: that pressure): ∫ p Q dt while p << K_f
// (H = p (1 - p/2K_f + ...); with p = 0.3 K_f the difference was 13%, in a test). The
// faces' work is Σ p ΔV with the pressure their forces had over the step (the mid-step
// prediction's); lumped half-volumes and the forces of the same halves make it the
// forces' work to first order.
// No floating-point atomics: every sum is over a CSR list in fixed order.
//
// GAS ([fluid.gas]): the fluid is a polytropic gas, p = p0 (V₀/V)^γ with V₀ its volume at
// the reference density ρ0 (GAS_P0, GAS_GAMMA from the host); its energy at a vertex is
// U = p V / (γ - 1) (∂U/∂V = -p at fixed V₀: an isentropic gas), and fluid entering at p
// brings H = γ/(γ - 1) p0 (p/p0)^((γ-1)/γ) per unit V₀. The source is the blast hole:
// gas_hole_state (one work-item, after the sub-steps) sets the hole's (p, V, V₀, U) from
// the gas the wall vertices have not taken and the wall polygon's area; in the next
// step's sub-steps (fluid_substeps_group) the hole and its wall vertices come to a common
// pressure after each sub-step's fluxes, and its LOAD_GAS edges (boundary_loads.cl) push
// the wall with the hole's p.
// CAP_APERTURE (fluid.aperture_limit = "cap"): the conductance uses min(w_m, w_max) and a
// wider segment does not stop the run (the stable step holds; the volume is the true one).

// The state laws, apertures and rooms: cl_kernels/fluid_laws.cl (built ahead of this file).

// Whether CE4 e carries fluid: broken (status >= 1), or with DAMAGED_SEGMENTS softened at
// one of its three points (D_max > 0: past the peak of its law). Irreversible, so a
// segment never closes to the network again (cohesive_forces.cl keeps the same rule for
// the list of carriers, FLUID_CARRIERS).
inline bool segment_carries(const uint e, __global const int2* restrict status
#if DAMAGED_SEGMENTS
                            , __global const real* restrict gp_state
#endif
                            ) {
#if DAMAGED_SEGMENTS
  return status[e].x >= 1 || gp_state[9 * e] > (real)0 || gp_state[9 * e + 3] > (real)0 ||
         gp_state[9 * e + 6] > (real)0;
#else
  return status[e].x >= 1;
#endif
}

// One CE4's segment (fluid_segments, and the fused fluid_step_group below).
inline void segment_item(const uint e,
                             __global const uint4* restrict ce4_nodes,
                             __global const real2* restrict position,
                             __global const int2* restrict status,
#if DAMAGED_SEGMENTS
                             __global const real* restrict gp_state,
#endif
                             __global const real* restrict seg_h,
                             const real thickness,
                             const real residual,
                             const real max_aperture,
                             const real viscosity,
                             const int step,
                             __global real4* restrict seg_geom,
#if GAS
                             __global uchar* restrict seg_joined,
#endif
                             __global int* restrict too_wide) {
#if DAMAGED_SEGMENTS
  const bool carries = segment_carries(e, status, gp_state);
#else
  const bool carries = segment_carries(e, status);
#endif
  // A CE4 that does not carry now never has (carrying is irreversible: a closed or released
  // CE4 stays so, D_max only grows), so its seg_geom (and seg_joined) still hold the zeros
  // FluidFlow made them with or a checkpoint restored: nothing to write. Most CE4s of a
  // model are such, and the stage's cost on a GPU is these passes over every CE4.
  if (!carries) return;
#if GAS
  seg_joined[e] = seg_geom[e].z == (real)0;  // carries from this step on (its conductance is > 0 once it does)
#endif
  const uint4 nd = ce4_nodes[e];
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  const real h = seg_h[e];
#if GAS
  // Each half's mean opening (its open area over h/2) through the smooth aperture: the
  // halves' rooms (h/2) t w_a and (h/2) t w_b; for a thin crack the lumped h t (3 w_i + w_j)/8.
  const real2 m = (real)0.5 * (xi + xj), m2 = (real)0.5 * (xi2 + xj2);
  const real half_h = (real)0.5 * h;
  const real wa = gas_aperture(open_area(xi, m, m2, xi2) / half_h, residual);
  const real wb = gas_aperture(open_area(m, xj, xj2, m2) / half_h, residual);
#else
  const real2 chord = (xj - xi) + (xj2 - xi2);
  const real2 t = chord / length(chord);
  const real2 n = (real2)(t.y, -t.x);
  const real wa = fmax(dot(xi2 - xi, n), (real)0) + residual;
  const real wb = fmax(dot(xj2 - xj, n), (real)0) + residual;
#endif
  const real wm = (real)0.5 * (wa + wb);
#if CAP_APERTURE
  const real wc = fmin(wm, max_aperture);
  const real c = wc * wc * wc * thickness / ((real)12 * viscosity * h);
#else
  const real c = wm * wm * wm * thickness / ((real)12 * viscosity * h);
#endif
#if GAS
  seg_geom[e] = (real4)(half_h * thickness * wa, half_h * thickness * wb, c, wm);
#else
  seg_geom[e] = (real4)(h * thickness * ((real)3 * wa + wb) / (real)8, h * thickness * (wa + (real)3 * wb) / (real)8, c, wm);
#endif
#if !CAP_APERTURE
  if (fmax(wa, wb) > max_aperture) {
    atomic_min(&too_wide[0], (int)e);
    atomic_min(&too_wide[1], step);
  }
#endif
}

// The counters fluid_vertices and the sub-steps fill anew each step.
inline void reset_wet_count(__global uint* wet_count) {
  wet_count[0] = 0;  // fluid_vertices lists the wet vertices anew
  wet_count[1] = 0;  // and (ADAPTIVE) finds the network's largest rate anew
  wet_count[2] = 0;  // (the gas) and its densest vertex
}

// One work-item per CE4: its segment's rooms, conductance and mean aperture (seg_geom);
// work-item 0 resets the counters for fluid_vertices, next in the queue.
__kernel void fluid_segments(const uint n_ce4,
                             __global const uint4* restrict ce4_nodes,
                             __global const real2* restrict position,
                             __global const int2* restrict status,
#if DAMAGED_SEGMENTS
                             __global const real* restrict gp_state,
#endif
                             __global const real* restrict seg_h,
                             const real thickness,
                             const real residual,
                             const real max_aperture,
                             const real viscosity,
                             const int step,
                             __global real4* restrict seg_geom,
#if GAS
                             __global uchar* restrict seg_joined,
#endif
                             __global int* restrict too_wide,
                             __global uint* restrict wet_count) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  if (e == 0) reset_wet_count(wet_count);
  segment_item(e, ce4_nodes, position, status,
#if DAMAGED_SEGMENTS
               gp_state,
#endif
               seg_h, thickness, residual, max_aperture, viscosity, step, seg_geom,
#if GAS
               seg_joined,
#endif
               too_wide);
}

// vertex_state: (V₀ [m³], V [m³], p [Pa], U [J]); vertex_energy: (injection work [J],
// work of the pressure on the faces [J], injected V₀ [m³], viscous dissipation [J]),
// cumulative.
inline void vertex_item(const uint v,
                             __global const uint* restrict vertex_start,
                             __global const uint* restrict vertex_end,
                             __global const real4* restrict seg_geom,
                             const real bulk,
                             __global const uchar* restrict source,
#if LEAK_OFF
                             __global const real* restrict seg_exposed,
#endif
#if GAS
                             __global const uchar* restrict seg_joined,
#endif
                             __global real* restrict vertex_rate,
                             __global real4* restrict vertex_state,
                             __global real4* restrict vertex_energy,
                             __global real2* restrict front,
                             __global uint* restrict wet_count,
                             __global uint* restrict wet) {
  real volume = 0;
#if ADAPTIVE
  real conductance = 0;  // Σ c of its segments
#endif
#if GAS
  real joined = 0;  // the halves of the segments that joined the network this step
#endif
  bool flows = source[v] != 0;  // a sub-step can change this vertex: list it
  for (uint k = vertex_start[v]; k < vertex_start[v + 1]; ++k) {
    const uint end = vertex_end[k];
    const real4 g = seg_geom[end >> 1];
    volume += (end & 1u) ? g.y : g.x;
#if GAS
    if (seg_joined[end >> 1]) joined += (end & 1u) ? g.y : g.x;
#endif
    flows = flows || g.z != (real)0;
#if ADAPTIVE
    conductance += g.z;
#endif
#if LEAK_OFF
    flows = flows || seg_exposed[end >> 1] >= (real)0;
#endif
  }
  // The list's order depends on the atomics, its content does not, and each listed
  // vertex's sub-step reads only the copies: the results do not depend on the order.
  if (flows) wet[atomic_inc(wet_count)] = v;
#if ADAPTIVE
  // The vertex's rate K Σc / V (K = K_f, or γ p0 for the gas: the plan's modulus): the
  // explicit exchange is stable for Δt_s below 1 / max of it (Gershgorin), and the
  // sub-steps take half that (substeps_now). The maximum over the vertices is kept as a
  // float's bits in wet_count[1] (positive floats order as their bits): the same word
  // whatever the order of the atomics.
  if (volume > (real)0 && conductance > (real)0)
    atomic_max(&wet_count[1], as_uint((float)(FLUID_MODULUS * conductance / volume)));
#endif
  real4 s = vertex_state[v];
#if ADAPTIVE && GAS
  if (volume > (real)0 && s.x > (real)0) atomic_max(&wet_count[2], as_uint((float)fmin(s.x / volume, (real)1)));
#endif
#if GAS
  const bool wall = source[v] != 0;
  if (wall && s.y > (real)0 && volume != s.y) {
    // A wall vertex: its room opens on the hole, so its gas stays at the hole's density
    // (the ratio r = V₀/V the last sub-step's common fill left) while its room changes:
    // the hole gives or takes r ΔV of gas (injected V₀, which the sub-steps and
    // gas_hole_state take from the hole) and the faces work at the vertex's pressure of
    // the step's start, the hole's, which its forces had (its vertex_rate is 0: no
    // prediction). On its own isentrope a closing mouth's few mm² of gas stiffened into a
    // spring the step could not follow, and the gas swung between the hole and the wall
    // from step to step (the blasting case's own mesh stopped at 109 µs,
    // cases/blasting/README.md). The energy: injection ΔU + p ΔV (at a fixed r, U is
    // linear in V), the faces' work p ΔV of the segments that moved, and the room of those
    // that joined dry filled at p: p ΔV_joined lost (throttling).
    real4 en = vertex_energy[v];
    const real p_step = gas_pressure(s.x, mid_step_volume(s.y, vertex_rate[v]));
    const real v0 = s.x * (volume / s.y);
    en.x += (gas_energy(v0, volume) - s.w) + p_step * (volume - s.y);
    en.y += p_step * ((volume - joined) - s.y);
    en.z += v0 - s.x;
    en.w += p_step * joined;
    vertex_energy[v] = en;
    s.x = v0;
  }
  const real p = gas_pressure(s.x, volume);
  if (!wall && volume != s.y) {
    real4 en = vertex_energy[v];
    // The faces moved the old segments' room at the pressure their forces had; the room
    // of a segment that just joined was opened dry, and the gas expands into it freely:
    // what that expansion takes from its energy is lost (booked with the dissipation).
    const real moved = volume - joined;
    const real rate = vertex_rate[v];
    en.y += gas_pressure(s.x, mid_step_volume(s.y, rate)) * (moved - s.y);  // the forces' (mid-step) pressure
    vertex_rate[v] = moved - s.y;
    if (joined > (real)0 && s.x > (real)0)
      en.w += gas_energy(s.x, moved) - gas_energy(s.x, volume);
    vertex_energy[v] = en;
  } else {
    vertex_rate[v] = 0;
  }
#else
  const real d = fluid_excess(s.x, volume);
  const real p = bulk * d;
  if (volume != s.y) {
    real4 en = vertex_energy[v];
    en.y += liquid_face_pressure(s, vertex_rate[v]) * (volume - s.y);  // the forces' (mid-step) pressure
    vertex_energy[v] = en;
  }
#if PRESSURE_SOURCE
  vertex_rate[v] = source[v] ? (real)0 : volume - s.y;
#else
  vertex_rate[v] = volume - s.y;
#endif
#endif
#if GAS
  vertex_state[v] = (real4)(s.x, volume, p, gas_energy(s.x, volume));
#else
  vertex_state[v] = (real4)(s.x, volume, p, fluid_stored(bulk, volume, d));
#endif
  front[v] = (real2)(s.x, p);  // what the first sub-step's neighbours read
}

// One work-item per network vertex (vertex_item).
__kernel void fluid_vertices(const uint n_vertices,
                             __global const uint* restrict vertex_start,
                             __global const uint* restrict vertex_end,
                             __global const real4* restrict seg_geom,
                             const real bulk,
                             __global const uchar* restrict source,
#if LEAK_OFF
                             __global const real* restrict seg_exposed,
#endif
#if GAS
                             __global const uchar* restrict seg_joined,
#endif
                             __global real* restrict vertex_rate,
                             __global real4* restrict vertex_state,
                             __global real4* restrict vertex_energy,
                             __global real2* restrict front,
                             __global uint* restrict wet_count,
                             __global uint* restrict wet) {
  const uint v = get_global_id(0);
  if (v >= n_vertices) return;
  vertex_item(v, vertex_start, vertex_end, seg_geom, bulk, source,
#if LEAK_OFF
              seg_exposed,
#endif
#if GAS
              seg_joined,
#endif
              vertex_rate, vertex_state, vertex_energy, front, wet_count, wet);
}

#if ADAPTIVE
// The step's sub-steps (ADAPTIVE: a source constant in time or the gas's hole, no
// leak-off): the plan's count (`planned`, from fluid.max_aperture) or fewer, as many as
// the network's largest rate (fluid_vertices) asks for at the step's `safety`,
// ceil(Δt / (safety × 0.5 / rate)); the plan's own bound is 3 μ h² / (K w_max²), half the
// rate bound of a chain of equal segments of aperture w_max.
inline uint substeps_now(__global const uint* wet_count, const real dt, const real safety, const uint planned,
                         const real factor) {
  const real rate = (real)as_float(wet_count[1]) * factor;
  if (!(rate > (real)0)) return 1u;
  const real n = ceil(dt * rate / ((real)0.5 * safety));
  return n >= (real)planned ? planned : (n < (real)1 ? 1u : (uint)n);
}
#endif

// A sub-step's update of one vertex's state s (V₀, V, p, U) and energy en, in two parts
// that substep_vertex and the group kernel's local path share (the same operations in the
// same order: the same bits). vertex_flow: the net inflow's V₀ and the flow's loss at
// this vertex, its energy before less after the fluxes (the sum over the vertices is the
// viscous dissipation of the sub-step, exactly as the explicit update has it;
// Σ q (H_a - H_b) Δt_s over-counts it by the update's O(Δt_s²) term); returns the energy
// after the fluxes (the leak-off's reference).
inline real vertex_flow(real4* s, real4* en, const real inflow, const real bulk, const real dt_sub) {
  s->x += dt_sub * inflow;
#if GAS
  const real u_flowed = gas_energy(s->x, s->y);
#else
  const real u_flowed = fluid_stored(bulk, s->y, fluid_excess(s->x, s->y));
#endif
  en->w += s->w - u_flowed;
  return u_flowed;
}
// The source's fluid (a liquid's: the gas's wall vertices are filled after the sub-step's
// fluxes, together with the hole, in fluid_substeps_group), then the new p and U.
inline void vertex_source_and_state(real4* s, real4* en, const bool source, const real source_value,
                                    const real bulk, const real dt_sub) {
#if !GAS
  if (source && s->y > (real)0) {
#if PRESSURE_SOURCE
    // Held at p_s: the source fills the vertex to V (1 + p_s / K_f) and works at p_s.
    const real added = s->y * ((real)1 + source_value / bulk) - s->x;
    const real h_work = bulk * log1p(source_value / bulk);
#else
    const real added = dt_sub * source_value;
    const real h_work = bulk * log1p(fluid_excess(s->x + (real)0.5 * added, s->y));  // at the sub-step's middle
#endif
    s->x += added;
    en->x += h_work * added;
    en->z += added;
  }
  const real d = fluid_excess(s->x, s->y);
  s->z = bulk * d;
  s->w = fluid_stored(bulk, s->y, d);
#else
  s->z = gas_pressure(s->x, s->y);
  s->w = gas_energy(s->x, s->y);
#endif
}

// One vertex's sub-step (fluid_substep and fluid_substeps_group below).
inline void substep_vertex(const uint v,
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
  real4 en = vertex_energy[v];
  const real u_flowed = vertex_flow(&s, &en, inflow, bulk, dt_sub);
  (void)u_flowed;  // the leak-off's reference
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
  vertex_source_and_state(&s, &en, source[v] != 0, source_value, bulk, dt_sub);
  vertex_energy[v] = en;
  vertex_state[v] = s;
  back[v] = (real2)(s.x, s.z);
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
// are held at `source_value` [Pa]; else each takes source_value [m³/s] of V₀. (Not built
// for the gas: it always takes fluid_substeps_group, which follows the hole's gas.)
#if !GAS
__kernel void fluid_substep(__global uint* restrict wet_count,
                            __global const uint* restrict wet,
                            __global const uint* restrict vertex_start,
                            __global const uint* restrict vertex_end,
                            __global const uint2* restrict seg_vertex,
                            __global const real4* restrict seg_geom,
                            __global const real2* restrict front,
                            __global const uchar* restrict source,
                            const real source_value,
                            const real bulk,
#if ADAPTIVE
                            const real dt,
                            const real safety,
                            const uint planned,
                            const uint k_sub,
#else
                            const real dt_sub,
#endif
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
#if ADAPTIVE
  // Launched `planned` times; the launches past the step's own count do nothing.
  const uint n_sub = substeps_now(wet_count, dt, safety, planned, (real)1);
  if (i == 0 && k_sub == 0) wet_count[3] = n_sub;  // the step's count, for the history
  if (k_sub >= n_sub) return;
  const real dt_sub = dt / (real)n_sub;
#endif
  if (i >= wet_count[0]) return;
  substep_vertex(wet[i], vertex_start, vertex_end, seg_vertex, seg_geom, front, source, source_value, bulk, dt_sub
#if LEAK_OFF
                 , t_sub, leak_off, thickness, seg_h, seg_exposed, vertex_leak
#endif
                 , vertex_state, vertex_energy, back);
}
#endif

#if !LEAK_OFF
// All sub-steps of a step in one launch of one work-group of FLUID_GROUP work-items
// (the host takes it for a source constant in time, or the gas's hole, and no leak-off):
// work-item l does the wet vertices l, l + FLUID_GROUP, ..., sub-step k reading `front`
// and writing `back` for even k, the other way for odd k, a barrier between sub-steps.
// Each vertex's sub-step is fluid_substep's, with the same operands: the same bits as
// n_sub launches of it, without their launch costs (the fluid's cost on a small network).
// FLUID_LOCAL (a liquid, at most FLUID_GROUP wet vertices of at most FLUID_LOCAL_DEGREE
// CE4 ends each): work-item l keeps wet vertex l's state, energy and segments (their
// conductances and the other ends' places in the wet list) in registers and the two
// copies in local memory, so a sub-step reads no global memory and waits on a local
// barrier only (on an H100 the global path's sub-step was about 0.9 µs, the chain of
// dependent loads through the CSR lists and the copies: the small fluid rows' cost). The
// same operations in the same order: the same bits.
#define FLUID_LOCAL_DEGREE 12
// The body of fluid_substeps_group, shared with the fused fluid_step_group: its local
// memory is the kernel's (OpenCL C 1.2 declares __local at a kernel's scope): hole_local
// 3 reals (the gas), local_copy 2 × FLUID_GROUP, too_many one word.
inline void substeps_in_group(const uint planned,
                          __global uint* restrict wet_count,
                          __global const uint* restrict wet,
                          __global const uint* restrict vertex_start,
                          __global const uint* restrict vertex_end,
                          __global const uint2* restrict seg_vertex,
                          __global const real4* restrict seg_geom,
                          __global real2* front,
                          __global const uchar* restrict source,
                          const real source_value,
                          const real bulk,
#if ADAPTIVE
                          const real dt,
                          const real safety,
#else
                          const real dt_sub,
#endif
#if GAS
                          __global const real4* restrict gas_hole,
                          const uint n_source,
                          __global const uint* restrict source_vertices,
                          const real hole_gas0,
#endif
                          __global real4* restrict vertex_state,
                          __global real4* restrict vertex_energy,
                          __global real2* back,
                          __local real* hole_local,
                          __local real2* local_copy,
                          __local uint* too_many) {
  const uint n = wet_count[0];
#if GAS
  // The hole's pressure and gas anew after each sub-step (work-item 0, the wall vertices'
  // intake in source order, the hole's volume of the step's start: the geometry does not
  // move during the sub-steps), so that a hole that empties fast is not drawn on at the
  // pressure of the step's start; each wall vertex takes at most its share of what is left.
  // hole_local: (r, V₀ left, H_eff) of the last sub-step's fill
  // The gas left in the hole as gas_hole_state sums it (source order), after this step's
  // fluid_vertices gave or took the wall vertices' changes of room.
  if (get_local_id(0) == 0) {
    real taken = 0;
    for (uint j = 0; j < n_source; ++j) taken += vertex_energy[source_vertices[j]].z;
    hole_local[0] = gas_hole[0].x, hole_local[1] = hole_gas0 - taken;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
#endif
#if ADAPTIVE && GAS
  // The gas's modulus is γ p, γ p0 r^(γ-1) at the density ratio r = V₀/V (the plateau's r
  // is 1): the exchange's fastest rate is that of the densest room the flow can fill, the
  // hole's (the flow only evens densities out) or a vertex squeezed denser (wet_count[2]).
  // The plan's count took r = 1, the hole's full gas; a blast's hole is at r 0.46 after
  // 100 µs, 0.17 after 400 µs (docs/performance-notes.md, session 22).
  const real4 hole = gas_hole[0];
  const real r_hole = hole.y > (real)0 ? hole.z / hole.y : (real)1;
  const real r_max = fmin(fmax((real)as_float(wet_count[2]), r_hole), (real)1);
  const real modulus_share = r_max > (real)0 ? pow(r_max, (real)GAS_GAMMA - (real)1) : (real)1;
  const uint n_sub = substeps_now(wet_count, dt, safety, planned, modulus_share);
  const real dt_sub = dt / (real)n_sub;
#elif ADAPTIVE
  const uint n_sub = substeps_now(wet_count, dt, safety, planned, (real)1);
  const real dt_sub = dt / (real)n_sub;
#else
  const uint n_sub = planned;
#endif
#if ADAPTIVE
  // The step's count, for the history (every item read wet_count[0] above, and no item
  // reads this word).
  if (get_local_id(0) == 0) wet_count[3] = n_sub;
#endif
#if FLUID_LOCAL && !GAS
  if (n <= FLUID_GROUP) {  // the same for every work-item
    const uint l = get_local_id(0);
    if (l == 0) *too_many = 0;
    barrier(CLK_LOCAL_MEM_FENCE);
    uint v = 0, start = 0, degree = 0;
    if (l < n) {
      v = wet[l];
      start = vertex_start[v];
      degree = vertex_start[v + 1] - start;
      if (degree > FLUID_LOCAL_DEGREE) atomic_or(too_many, 1u);
      // The wet list's place of each wet vertex, in the `back` copy this path does not use
      // (both ends of an open segment are wet: fluid_vertices lists them).
      back[v].x = (real)l;
    }
    barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
    if (!*too_many) {
      real4 s = (real4)(0), en = (real4)(0);
      bool src = false;
      real c[FLUID_LOCAL_DEGREE];
      uint other[FLUID_LOCAL_DEGREE], odd = 0;  // the other end's place; bit d: this vertex is the segment's b end
      if (l < n) {
        s = vertex_state[v];
        en = vertex_energy[v];
        src = source[v] != 0;
        for (uint d = 0; d < FLUID_LOCAL_DEGREE; ++d) {
          c[d] = (real)0;
          other[d] = l;
          if (d < degree) {
            const uint end = vertex_end[start + d];
            c[d] = seg_geom[end >> 1].z;
            if (c[d] != (real)0) {
              const uint2 ab = seg_vertex[end >> 1];
              other[d] = (uint)back[(end & 1u) ? ab.x : ab.y].x;
            }
            if (end & 1u) odd |= 1u << d;
          }
        }
        local_copy[l] = front[v];
      }
      barrier(CLK_LOCAL_MEM_FENCE);
      for (uint k = 0; k < n_sub; ++k) {
        __local real2* from = local_copy + (k & 1u) * FLUID_GROUP;
        __local real2* to = local_copy + (1u - (k & 1u)) * FLUID_GROUP;
        if (l < n) {
          real inflow = 0;
          for (uint d = 0; d < FLUID_LOCAL_DEGREE; ++d) {
            if (c[d] != (real)0) {  // (zero past the degree)
              const bool is_b = (odd >> d) & 1u;
              const real pa = is_b ? from[other[d]].y : from[l].y, pb = is_b ? from[l].y : from[other[d]].y;
              const real q = c[d] * (pa - pb);
              inflow += is_b ? q : -q;
            }
          }
          if (inflow != (real)0 || src) {
            vertex_flow(&s, &en, inflow, bulk, dt_sub);
            vertex_source_and_state(&s, &en, src, source_value, bulk, dt_sub);
          }
          to[l] = (real2)(s.x, s.z);
        }
        barrier(CLK_LOCAL_MEM_FENCE);
      }
      if (l < n) {
        vertex_state[v] = s;
        vertex_energy[v] = en;
      }
      return;
    }
  }
#endif
  for (uint k = 0; k < n_sub; ++k) {
    __global real2* from = (k & 1u) ? back : front;
    __global real2* to = (k & 1u) ? front : back;
    for (uint i = get_local_id(0); i < n; i += FLUID_GROUP)
      substep_vertex(wet[i], vertex_start, vertex_end, seg_vertex, seg_geom, from, source, source_value, bulk, dt_sub,
                     vertex_state, vertex_energy, to);
#if GAS
    // The hole and its wall vertices, after the sub-step's fluxes, come to their common
    // pressure: the gas of the hole and of the wall vertices spread over their joint room
    // (ratio r of V₀ to volume). Filling the wall vertices to the hole's pressure of the
    // sub-step's start instead was unstable once the wall's rooms (the cracks opened at
    // the wall) held as much as the hole: what they took dropped the hole's pressure below
    // theirs (p ∝ ρ^γ) and the next sub-step gave it back, booking injection work and
    // dissipation a hundred times the gas's energy (cases/blasting/README.md). The hole
    // gives its energy drop U(L) - U(L') (volume of the step's start, isentropic), booked
    // at the wall vertices as injection in proportion to what each takes (H_eff per unit
    // V₀; a vertex that gives back is charged at the same rate).
    barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
    if (get_local_id(0) == 0) {
      const real v_hole = gas_hole[0].y, left = hole_local[1];
      real gas = fmax(left, (real)0), room = v_hole;
      for (uint j = 0; j < n_source; ++j) {
        const real4 st = vertex_state[source_vertices[j]];
        if (st.y > (real)0) gas += st.x, room += st.y;
      }
      const real r = gas / room, left_after = v_hole * r, given = left - left_after;
      const real drop = gas_energy(left, v_hole) - gas_energy(left_after, v_hole);
      hole_local[0] = r;
      hole_local[1] = left_after;
      hole_local[2] = given != (real)0 ? drop / given : gas_enthalpy(gas_pressure(left_after, v_hole));
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    const real r = hole_local[0], h_eff = hole_local[2];
    for (uint j = get_local_id(0); j < n_source; j += FLUID_GROUP) {
      const uint w = source_vertices[j];
      real4 st = vertex_state[w];
      if (!(st.y > (real)0)) continue;
      const real added = st.y * r - st.x;
      real4 en = vertex_energy[w];
      const real u_flowed = st.w;
      st.x += added;
      st.z = gas_pressure(st.x, st.y);
      st.w = gas_energy(st.x, st.y);
      en.x += h_eff * added;
      en.z += added;
      en.w += h_eff * added - (st.w - u_flowed);  // the mixing's loss (throttling)
      vertex_energy[w] = en;
      vertex_state[w] = st;
      to[w] = (real2)(st.x, st.z);
    }
    barrier(CLK_GLOBAL_MEM_FENCE);
#else
    barrier(CLK_GLOBAL_MEM_FENCE);
#endif
  }
}

// One work-group of FLUID_GROUP items: the step's sub-steps (substeps_in_group).
__kernel __attribute__((reqd_work_group_size(FLUID_GROUP, 1, 1)))
void fluid_substeps_group(const uint planned,
                          __global uint* restrict wet_count,
                          __global const uint* restrict wet,
                          __global const uint* restrict vertex_start,
                          __global const uint* restrict vertex_end,
                          __global const uint2* restrict seg_vertex,
                          __global const real4* restrict seg_geom,
                          __global real2* front,
                          __global const uchar* restrict source,
                          const real source_value,
                          const real bulk,
#if ADAPTIVE
                          const real dt,
                          const real safety,
#else
                          const real dt_sub,
#endif
#if GAS
                          __global const real4* restrict gas_hole,
                          const uint n_source,
                          __global const uint* restrict source_vertices,
                          const real hole_gas0,
#endif
                          __global real4* restrict vertex_state,
                          __global real4* restrict vertex_energy,
                          __global real2* back) {
  __local real hole_local[3];
  __local real2 local_copy[2 * FLUID_GROUP];
  __local uint too_many;
  substeps_in_group(planned, wet_count, wet, vertex_start, vertex_end, seg_vertex, seg_geom, front, source,
                    source_value, bulk,
#if ADAPTIVE
                    dt, safety,
#else
                    dt_sub,
#endif
#if GAS
                    gas_hole, n_source, source_vertices, hole_gas0,
#endif
                    vertex_state, vertex_energy, back, hole_local, local_copy, &too_many);
}
#endif

#if GAS
// One work-item (the rest return): the blast hole's gas at the end of the step, from the
// wall polygon's area on the step's positions (shoelace, in polygon order; the wall is
// walked clockwise, a crack's mouth closing it between two copies of a vertex) and the
// gas the wall vertices have taken so far (their injected V₀, in source order):
// gas_hole = (p, V, V₀ left, U) with p = p0 (V₀/V)^γ, U = p V / (γ - 1). The next step's
// wall loads and sub-steps read p; no atomics, the same bits every run.
__kernel void gas_hole_state(const uint n_polygon,
                             __global const uint* restrict polygon,
                             __global const real2* restrict position,
                             const real thickness,
                             const uint n_source,
                             __global const uint* restrict source_vertices,
                             __global const real4* restrict vertex_energy,
                             const real hole_gas0,
                             __global real4* restrict gas_hole) {
  if (get_global_id(0) != 0) return;
  real twice_area = 0;
  for (uint i = 0; i < n_polygon; ++i) {
    const real2 a = position[polygon[i]], b = position[polygon[i + 1 < n_polygon ? i + 1 : 0]];
    twice_area += a.x * b.y - b.x * a.y;
  }
  const real volume = (real)-0.5 * twice_area * thickness;
  real taken = 0;
  for (uint k = 0; k < n_source; ++k) taken += vertex_energy[source_vertices[k]].z;
  const real left = hole_gas0 - taken;
  const real p = gas_pressure(left, volume);
  gas_hole[0] = (real4)(p, volume, left, gas_energy(left, volume));
}
#endif

// One CE4's pressure forces into its four slots (fluid_forces, fluid_step_group).
inline void forces_item(const uint e,
                           __global const uint4* restrict ce4_nodes,
                           __global const real2* restrict position,
                           __global const uint2* restrict seg_vertex,
                           __global const real4* restrict seg_geom,
                           __global const real* restrict seg_h,
                           __global const real4* restrict vertex_state,
                           __global const real* restrict vertex_rate,
#if GAS
                           const real residual,
#endif
                           const real thickness,
                           __global real2* restrict fluid_slots,
                           __global uchar* restrict loaded_node) {
  // A segment that has never carried (its mean aperture w is at least w_r > 0 once it
  // does): its four slots still hold the zeros FluidFlow made them with.
  if (seg_geom[e].w == (real)0) return;
  const uint4 nd = ce4_nodes[e];
  // Its four nodes' flags, before the gather reads the slots (node_gather.cl reads the
  // fluid slots only at flagged nodes; every work-item that sets one stores the same 1).
  if (loaded_node[nd.x] == 0) loaded_node[nd.x] = 1;
  if (loaded_node[nd.y] == 0) loaded_node[nd.y] = 1;
  if (loaded_node[nd.z] == 0) loaded_node[nd.z] = 1;
  if (loaded_node[nd.w] == 0) loaded_node[nd.w] = 1;
  const real2 xi = position[nd.x], xj = position[nd.y], xj2 = position[nd.z], xi2 = position[nd.w];
  const uint2 ab = seg_vertex[e];
  const real4 sa = vertex_state[ab.x], sb = vertex_state[ab.y];
#if GAS
  // The pressure at the step's middle: the vertex's volume moved on by half the change of
  // the last step (a predictor: the forces' work is then the gas's ∫p dV to second order;
  // with the step-start pressure the fast-expanding gas gave the solid p ΔV, more than the
  // isentrope gives, 1.4% of the blast's energy in tests/data/cases/gas_small.toml); a
  // wall vertex's rate is 0: the hole's pressure of the step's start (fluid_vertices).
  const real pa = gas_pressure(sa.x, mid_step_volume(sa.y, vertex_rate[ab.x]));
  const real pb = gas_pressure(sb.x, mid_step_volume(sb.y, vertex_rate[ab.y]));
  // The forces are the exact gradient of the fluid's work p_a V_a + p_b V_b over the four
  // nodes (the gas's large, fast volume changes make any other force create or lose
  // energy): V = (h/2) t w(A / (h/2)) per half (fluid_segments), so ∂V/∂x = t w'(·) ∂A/∂x,
  // and a midpoint's gradient goes half to each of its face's nodes.
  const real half_h = (real)0.5 * seg_h[e];
  const real2 m = (real)0.5 * (xi + xj), m2 = (real)0.5 * (xi2 + xj2);
  const real fa = pa * thickness * gas_aperture_slope(open_area(xi, m, m2, xi2) / half_h, residual);
  const real fb = pb * thickness * gas_aperture_slope(open_area(m, xj, xj2, m2) / half_h, residual);
  const real2 a1 = perp(m2 - xi), a2 = perp(xi2 - m);  // the i-half's (x_i, m, m', x_i')
  const real2 b1 = perp(xj2 - m), b2 = perp(m2 - xj);  // the j-half's (m, x_j, x_j', m')
  const real2 on_m = (real)0.5 * (-fa * a1 + fb * b2), on_m2 = (real)0.5 * (-fa * a2 + fb * b1);
  fluid_slots[4 * e] = (real)0.5 * fa * a2 + (real)0.5 * on_m;       // i
  fluid_slots[4 * e + 1] = (real)-0.5 * fb * b1 + (real)0.5 * on_m;  // j
  fluid_slots[4 * e + 2] = (real)-0.5 * fb * b2 + (real)0.5 * on_m2; // j'
  fluid_slots[4 * e + 3] = (real)0.5 * fa * a1 + (real)0.5 * on_m2;  // i'
#else
  const real2 chord = (xj - xi) + (xj2 - xi2);
  const real2 t = chord / length(chord);
  const real2 n = (real2)(t.y, -t.x);
  const real pa = liquid_face_pressure(sa, vertex_rate[ab.x]), pb = liquid_face_pressure(sb, vertex_rate[ab.y]);
  const real ht = seg_h[e] * thickness / (real)8;
  const real2 fa = ht * ((real)3 * pa + pb) * n, fb = ht * (pa + (real)3 * pb) * n;
  fluid_slots[4 * e] = -fa;      // i: face 1 pushed away from face 2
  fluid_slots[4 * e + 1] = -fb;  // j
  fluid_slots[4 * e + 2] = fb;   // j'
  fluid_slots[4 * e + 3] = fa;   // i'
#endif
}

// One work-item per CE4 (forces_item).
__kernel void fluid_forces(const uint n_ce4,
                           __global const uint4* restrict ce4_nodes,
                           __global const real2* restrict position,
                           __global const uint2* restrict seg_vertex,
                           __global const real4* restrict seg_geom,
                           __global const real* restrict seg_h,
                           __global const real4* restrict vertex_state,
                           __global const real* restrict vertex_rate,
#if GAS
                           const real residual,
#endif
                           const real thickness,
                           __global real2* restrict fluid_slots,
                           __global uchar* restrict fluid_loaded_node) {
  const uint e = get_global_id(0);
  if (e >= n_ce4) return;
  forces_item(e, ce4_nodes, position, seg_vertex, seg_geom, seg_h, vertex_state, vertex_rate,
#if GAS
              residual,
#endif
              thickness, fluid_slots, fluid_loaded_node);
}

#if FUSED && !GAS && !LEAK_OFF
// The network's lists for the fused step: the carrying CE4s (cohesive_forces appends each
// in the step it starts to carry: engine/stages/fluid_carriers.hpp) and the network's
// vertices (the source's and the carriers' ends: a vertex with no carrying segment holds
// no fluid, and its fluid_vertices pass writes back the zeros it has). Both only grow;
// their order depends on the atomics, their content does not, and no result depends on
// the order (each CE4 and each vertex is one item's, as in the four launches).
inline void join_network(const uint v, __global uint* in_net, __global uint* net_vertices, __global uint* net_count) {
  if (atomic_xchg(&in_net[v], 1u) == 0u) net_vertices[atomic_inc(&net_count[0])] = v;
}

// One work-item per vertex: empties both lists (FluidFlow rebuilds them when it starts
// and when it restores a checkpoint: fluid_network_scan, next in the queue).
__kernel void fluid_network_clear(const uint n_vertices,
                                  __global uint* restrict in_net,
                                  __global uint* restrict net_count,
                                  __global uint* restrict carrier_count) {
  const uint v = get_global_id(0);
  if (v == 0) {
    net_count[0] = 0;  // vertices in the network
    net_count[1] = 0;  // carriers whose ends have joined it
    carrier_count[0] = 0;
  }
  if (v < n_vertices) in_net[v] = 0;
}

// One work-item per CE4 and per vertex (the larger count): the CE4s that carry now into
// the carriers' list, the source's vertices into the network's (the carriers' ends join
// it in fluid_step_group).
__kernel void fluid_network_scan(const uint n_ce4,
                                 const uint n_vertices,
                                 __global const int2* restrict status,
#if DAMAGED_SEGMENTS
                                 __global const real* restrict gp_state,
#endif
                                 __global const uchar* restrict source,
                                 __global uint* restrict carriers,
                                 __global uint* restrict carrier_count,
                                 __global uint* restrict in_net,
                                 __global uint* restrict net_vertices,
                                 __global uint* restrict net_count) {
  const uint i = get_global_id(0);
#if DAMAGED_SEGMENTS
  if (i < n_ce4 && segment_carries(i, status, gp_state)) carriers[atomic_inc(carrier_count)] = i;
#else
  if (i < n_ce4 && segment_carries(i, status)) carriers[atomic_inc(carrier_count)] = i;
#endif
  if (i < n_vertices && source[i]) join_network(i, in_net, net_vertices, net_count);
}

// The fused step's arguments, but for the four a kernel that carries the step as its
// first work-group shares with it (position, thickness, step and, ADAPTIVE, dt):
// fluid_step_group below, and triangle_forces.cl's FLUID_HEAD (the step in the triangle
// stage's launch). FLUID_STEP_PASS passes them on in the same order.
#if DAMAGED_SEGMENTS
#define FLUID_STEP_GP_ARG __global const real* restrict gp_state,
#define FLUID_STEP_GP_PASS gp_state,
#else
#define FLUID_STEP_GP_ARG
#define FLUID_STEP_GP_PASS
#endif
#if ADAPTIVE
#define FLUID_STEP_DT_ARG const real safety,
#define FLUID_STEP_DT_PASS safety,
#else
#define FLUID_STEP_DT_ARG const real dt_sub,
#define FLUID_STEP_DT_PASS dt_sub,
#endif
#define FLUID_STEP_ARGS                                                                                            \
  __global const uint *restrict carriers, __global const uint *restrict carrier_count, __global uint *in_net,     \
      __global uint *net_vertices, __global uint *net_count, __global const uint4 *restrict ce4_nodes,             \
      __global const int2 *restrict status, FLUID_STEP_GP_ARG __global const real *restrict seg_h,                 \
      const real residual, const real max_aperture, const real viscosity, __global real4 *seg_geom,                \
      __global int *too_wide, __global const uint *restrict vertex_start, __global const uint *restrict vertex_end, \
      __global const uint2 *restrict seg_vertex, const real bulk, __global const uchar *restrict source,            \
      const real source_value, const uint planned, FLUID_STEP_DT_ARG __global real *vertex_rate,                   \
      __global real4 *vertex_state, __global real4 *vertex_energy, __global real2 *front, __global real2 *back,     \
      __global uint *wet_count, __global uint *wet, __global real2 *fluid_slots, __global uchar *fluid_loaded_node
#define FLUID_STEP_PASS                                                                                           \
  carriers, carrier_count, in_net, net_vertices, net_count, ce4_nodes, status, FLUID_STEP_GP_PASS seg_h, residual, \
      max_aperture, viscosity, seg_geom, too_wide, vertex_start, vertex_end, seg_vertex, bulk, source,             \
      source_value, planned, FLUID_STEP_DT_PASS vertex_rate, vertex_state, vertex_energy, front, back, wet_count,  \
      wet, fluid_slots, fluid_loaded_node

// The liquid's whole step by one work-group of FLUID_GROUP items (FUSED: each of the
// stage's four launches cost about what a small model's mechanics costs on a GPU, issue
// 32's fluid rows): the new carriers' ends join the network in the segments' pass,
// work-item l doing the carriers l, l + FLUID_GROUP, ... of fluid_segments; then the
// network's vertices likewise of fluid_vertices, the sub-steps of fluid_substeps_group and
// the carriers of fluid_forces, a barrier between the passes. A CE4 that does not carry
// and a vertex outside the network do nothing in those kernels, and each item's work is
// theirs on the same operands: the same bits as the four launches, at a cost that follows
// the network, not the model. Its local memory is the calling kernel's (hole_local 3
// reals, local_copy 2 × FLUID_GROUP real2, too_many one word); `dt` is read only ADAPTIVE.
inline void fluid_step(__global const real2* restrict position, const real thickness, const int step, const real dt,
                       FLUID_STEP_ARGS, __local real* hole_local, __local real2* local_copy, __local uint* too_many) {
  const uint l = get_local_id(0);
  const uint n_carriers = carrier_count[0], joined = net_count[1];
  for (uint i = joined + l; i < n_carriers; i += FLUID_GROUP) {
    const uint2 ab = seg_vertex[carriers[i]];
    join_network(ab.x, in_net, net_vertices, net_count);
    join_network(ab.y, in_net, net_vertices, net_count);
  }
  if (l == 0) reset_wet_count(wet_count);
  // The segments do not read what the joins write (in_net, net_vertices, net_count), so
  // both passes share one barrier: their memory latencies overlap.
  for (uint i = l; i < n_carriers; i += FLUID_GROUP)
    segment_item(carriers[i], ce4_nodes, position, status,
#if DAMAGED_SEGMENTS
                 gp_state,
#endif
                 seg_h, thickness, residual, max_aperture, viscosity, step, seg_geom, too_wide);
  barrier(CLK_GLOBAL_MEM_FENCE);
  if (l == 0) net_count[1] = n_carriers;  // (every item read the old value above)
  const uint n_network = net_count[0];
  for (uint i = l; i < n_network; i += FLUID_GROUP)
    vertex_item(net_vertices[i], vertex_start, vertex_end, seg_geom, bulk, source, vertex_rate, vertex_state,
                vertex_energy, front, wet_count, wet);
  barrier(CLK_GLOBAL_MEM_FENCE);
  substeps_in_group(planned, wet_count, wet, vertex_start, vertex_end, seg_vertex, seg_geom, front, source,
                    source_value, bulk,
#if ADAPTIVE
                    dt, safety,
#else
                    dt_sub,
#endif
                    vertex_state, vertex_energy, back, hole_local, local_copy, too_many);
  barrier(CLK_GLOBAL_MEM_FENCE);
  for (uint i = l; i < n_carriers; i += FLUID_GROUP)
    forces_item(carriers[i], ce4_nodes, position, seg_vertex, seg_geom, seg_h, vertex_state, vertex_rate, thickness,
                fluid_slots, fluid_loaded_node);
}

// One work-group of FLUID_GROUP items: the liquid's step (fluid_step), on its own launch.
__kernel __attribute__((reqd_work_group_size(FLUID_GROUP, 1, 1)))
void fluid_step_group(__global const real2* restrict position,
                      const real thickness,
                      const int step,
#if ADAPTIVE
                      const real dt,
#endif
                      FLUID_STEP_ARGS) {
  __local real hole_local[3];
  __local real2 local_copy[2 * FLUID_GROUP];
  __local uint too_many;
#if !ADAPTIVE
  const real dt = 0;  // (read only ADAPTIVE)
#endif
  fluid_step(position, thickness, step, dt, FLUID_STEP_PASS, hole_local, local_copy, &too_many);
}
#endif
#ifdef FLUID_NO_CONTRACT
#pragma OPENCL FP_CONTRACT ON
#endif
