// Loads on boundary edges. Edge (a, b) is ordered so that the body lies on its left: its
// outward normal is (e.y, -e.x)/|e|, e = b - a. One row of load_table per load,
// (kind, p1, p2, p3):
//   LOAD_TRACTION  (τx, τy, rise): dead load per reference length, f = τ L₀ t, ramped.
//   LOAD_PRESSURE  (p, rise, -): follower load normal to the current edge,
//                  f = -p n L t (positive p pushes into the body), ramped.
//   LOAD_BLAST     (P₀/(e^{-αt₀} - e^{-βt₀}), α, β): the pressure of Eq. 21, as above.
//   LOAD_TABLE     (first point, point count, -): pressure interpolated linearly in
//                  pressure_points (time, value), held at the end values outside them.
//   LOAD_ABSORBING (material, -, -): viscous tractions of Eq. 20, t = -Z v with the
//                  impedance Z = (ρ Γ)^½, Γ_ik = C_ijkl n_j n_l the acoustic tensor of
//                  the adjacent material for the current normal n (isotropic:
//                  Z = ρV_p nn + ρV_s ss). Each node gets the dashpot of half the
//                  edge acting on its own velocity (a lumped dashpot).
//   LOAD_IN_SITU   (σ₀xx, σ₀yy, σ₀xy at the datum) and, in the next row, (datum,
//                  dσ₀/d depth for xx, yy, xy): the traction σ₀(y)·n of the in-situ field
//                  on the reference edge (a dead load, built with IN_SITU_LOADS only). σ₀
//                  is linear along the edge, so its consistent nodal forces are
//                  L₀ t (2 T_a + T_b)/6 and L₀ t (T_a + 2 T_b)/6 (T the traction at the
//                  node): exactly what the triangles' constant stresses at their
//                  centroids and the lumped weight ask of the boundary.
//   LOAD_GAS       (-, -, -): [fluid.gas]'s hole, the follower pressure gas_hole.x that
//                  the fluid stage computed at the end of the last step from the gas left in
//                  the hole and the hole's volume (built with GAS_LOADS only).
// Loads other than the absorbing and in-situ ones put half of f on each node. The force on each
// node is written to the edge's two slots (the node gather sums them).
// Energy account: before overwriting its slots the edge adds the work its forces did over
// the last step, by the trapezoid rule in time, ½ (f_before + f_now)·(x_now - x_before)
// per node, with x_now - x_before = v Δt (v is the velocity that made that move). That is
// exact for a force linear in time over the step and consistent with the integrator (see
// integrate.cl). Absorbing edges book minus it as absorbed energy, the others as load
// work; the edge adds both to its own totals in edge_energy (summed by the host in edge
// order at history rows: engine/energy.hpp). The first step has no "before" and adds nothing.
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).
// The kinds' values (LOAD_*) are defined in engine/layouts.hpp.

// Pressure at `time` from the table's points [first, first + count).
inline real table_pressure(__global const real2* points, uint first, uint count, real time) {
  if (time <= points[first].x) return points[first].y;
  for (uint k = first + 1; k < first + count; ++k) {
    const real2 p1 = points[k];
    if (time < p1.x) {
      const real2 p0 = points[k - 1];
      return p0.y + (p1.y - p0.y) * (time - p0.x) / (p1.x - p0.x);
    }
  }
  return points[first + count - 1].y;
}

// The 2x2 impedance (ρΓ)^½ of material `m` for unit normal n, as (Zxx, Zxy, Zyy).
// For a symmetric positive definite A: √A = (A + √det A I) / √(tr A + 2√det A).
inline real3 impedance(__global const real* material, real2 n) {
  const real c11 = material[MAT_C11], c12 = material[MAT_C12], c16 = material[MAT_C16];
  const real c22 = material[MAT_C22], c26 = material[MAT_C26], c66 = material[MAT_C66];
  const real rho = material[MAT_DENSITY];
  const real xx = n.x * n.x, xy = n.x * n.y, yy = n.y * n.y;
  const real gxx = rho * (c11 * xx + (real)2 * c16 * xy + c66 * yy);
  const real gxy = rho * (c16 * xx + (c12 + c66) * xy + c26 * yy);
  const real gyy = rho * (c66 * xx + (real)2 * c26 * xy + c22 * yy);
  const real s = sqrt(gxx * gyy - gxy * gxy);
  const real inv = (real)1 / sqrt(gxx + gyy + (real)2 * s);
  return (real3)((gxx + s) * inv, gxy * inv, (gyy + s) * inv);
}

// Work of edge e's forces over the last step (trapezoid rule; its slots still hold the
// forces of the step before).
inline real edge_work(__global const real2* edge_force, uint e, real2 fa, real2 fb, real2 va, real2 vb, real dt) {
  return (real)0.5 * dt * (dot(edge_force[2 * e] + fa, va) + dot(edge_force[2 * e + 1] + fb, vb));
}

// Edge e's two nodal forces, written to its slots; returns (load work, absorbed energy)
// of the last step, as above.
inline real4 edge_load_forces(const uint e,
                                   __global const uint2* restrict edge_nodes,
                                   __global const uint* restrict edge_load,
                                   __global const real4* restrict load_table,
                                   __global const real2* restrict pressure_points,
                                   __global const real* restrict materials,
                                   __global const real2* restrict edge_ref_position,
                                   __global const real2* restrict position,
                                   __global const real2* restrict velocity,
                                   const real thickness,
                                   const real time,
                                   __global real2* restrict edge_force,
                                   const real dt,
                                   const int step
#ifdef GAS_LOADS
                                   , __global const real4* restrict gas_hole
#endif
                                   ) {
  const uint2 ab = edge_nodes[e];
  const real4 load = load_table[edge_load[e]];
  const int kind = (int)load.x;
  const real2 ec = position[ab.y] - position[ab.x];
  const real2 outward_length = (real2)(ec.y, -ec.x);  // n L on the current edge
  if (kind == LOAD_ABSORBING) {
    const real edge_length = length(ec);
    const real2 n = outward_length / edge_length;
    const real3 z = impedance(materials + (uint)load.y * MATERIAL_STRIDE, n);
    const real node_share = (real)0.5 * edge_length * thickness;
    const real2 va = velocity[ab.x], vb = velocity[ab.y];
    const real2 fa = -node_share * (real2)(z.x * va.x + z.y * va.y, z.y * va.x + z.z * va.y);
    const real2 fb = -node_share * (real2)(z.x * vb.x + z.y * vb.y, z.y * vb.x + z.z * vb.y);
    const real work = step > 0 ? edge_work(edge_force, e, fa, fb, va, vb, dt) : (real)0;
    edge_force[2 * e] = fa;
    edge_force[2 * e + 1] = fb;
    return (real4)(0, -work, 0, 0);
  }
#ifdef IN_SITU_LOADS
  if (kind == LOAD_IN_SITU) {
    const real4 grad = load_table[edge_load[e] + 1];
    const real2 ra = edge_ref_position[2 * e], rb = edge_ref_position[2 * e + 1];
    const real2 nl = (real2)(rb.y - ra.y, ra.x - rb.x);  // outward normal × L₀ (reference edge)
    const real3 sa = load.yzw + (grad.x - ra.y) * grad.yzw, sb = load.yzw + (grad.x - rb.y) * grad.yzw;
    const real2 ta = (real2)(sa.x * nl.x + sa.z * nl.y, sa.z * nl.x + sa.y * nl.y);
    const real2 tb = (real2)(sb.x * nl.x + sb.z * nl.y, sb.z * nl.x + sb.y * nl.y);
    const real2 fa = thickness / (real)6 * ((real)2 * ta + tb), fb = thickness / (real)6 * (ta + (real)2 * tb);
    const real work = step > 0 ? edge_work(edge_force, e, fa, fb, velocity[ab.x], velocity[ab.y], dt) : (real)0;
    edge_force[2 * e] = fa;
    edge_force[2 * e + 1] = fb;
    return (real4)(work, 0, 0, 0);
  }
#endif
  real2 f;
  if (kind == LOAD_TRACTION) {
    const real ramp = load.w > (real)0 ? fmin(time / load.w, (real)1) : (real)1;
    const real2 e0 = edge_ref_position[2 * e + 1] - edge_ref_position[2 * e];
    f = ramp * thickness * length(e0) * (real2)(load.y, load.z);
  } else {
    real p;
    if (kind == LOAD_PRESSURE)
      p = load.y * (load.z > (real)0 ? fmin(time / load.z, (real)1) : (real)1);
    else if (kind == LOAD_BLAST)
      p = load.y * (exp(-load.z * time) - exp(-load.w * time));
#ifdef GAS_LOADS
    else if (kind == LOAD_GAS)
      p = gas_hole[0].x;
#endif
    else
      p = table_pressure(pressure_points, (uint)load.y, (uint)load.z, time);
    f = -p * thickness * outward_length;
  }
  const real2 each = (real)0.5 * f;
  const real work = step > 0 ? edge_work(edge_force, e, each, each, velocity[ab.x], velocity[ab.y], dt) : (real)0;
  edge_force[2 * e] = each;
  edge_force[2 * e + 1] = each;
  return (real4)(work, 0, 0, 0);
}

// The loaded edges' own arguments: the boundary_loads kernel's, but for the six a kernel
// that carries the edges as its tail shares with it (materials, position, velocity,
// thickness, dt, step): the kernel below and triangle_forces.cl's BOUNDARY_TAIL.
// BOUNDARY_EDGE_PASS passes them on in the same order.
#ifdef GAS_LOADS
#define BOUNDARY_GAS_ARG , __global const real4 *restrict gas_hole
#define BOUNDARY_GAS_PASS , gas_hole
#else
#define BOUNDARY_GAS_ARG
#define BOUNDARY_GAS_PASS
#endif
#define BOUNDARY_EDGE_ARGS                                                                                      \
  __global const uint2 *restrict edge_nodes, __global const uint *restrict edge_load,                          \
      __global const real4 *restrict load_table, __global const real2 *restrict pressure_points,               \
      __global const real2 *restrict edge_ref_position, const real time, __global real2 *restrict edge_force,  \
      __global real2 *restrict edge_energy BOUNDARY_GAS_ARG
#define BOUNDARY_EDGE_PASS \
  edge_nodes, edge_load, load_table, pressure_points, edge_ref_position, time, edge_force, edge_energy BOUNDARY_GAS_PASS

// Edge e's nodal forces and its share of the energy account (what one work-item of
// boundary_loads does; triangle_forces.cl's BOUNDARY_TAIL runs it in the same launch).
inline void boundary_edge(const uint e, __global const real* restrict materials, __global const real2* restrict position,
                          __global const real2* restrict velocity, const real thickness, const real dt, const int step,
                          BOUNDARY_EDGE_ARGS) {
  const real4 energy = edge_load_forces(e, edge_nodes, edge_load, load_table, pressure_points, materials, edge_ref_position,
                                        position, velocity, thickness, time, edge_force, dt, step BOUNDARY_GAS_PASS);
  edge_energy[e] += energy.xy;
}

// One work-item per loaded edge e: its nodal forces and its share of the energy account.
__kernel void boundary_loads(const uint n_edges,
                             __global const real* restrict materials,
                             __global const real2* restrict position,
                             __global const real2* restrict velocity,
                             const real thickness,
                             const real dt,
                             const int step,
                             BOUNDARY_EDGE_ARGS) {
  const uint e = get_global_id(0);
  if (e >= n_edges) return;
  boundary_edge(e, materials, position, velocity, thickness, dt, step, BOUNDARY_EDGE_PASS);
}
