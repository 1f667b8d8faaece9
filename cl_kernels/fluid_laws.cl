// FLUID_NO_CONTRACT (an experiment's build option, -DFLUID_NO_CONTRACT on the fluid_flow and
// triangle_forces stages through FDEM_CL_OPTIONS): no a·b + c of the fluid's code contracted
// into one rounding, so the compiler's choice of where to fuse cannot differ between the
// kernels that inline the same function (the fluid head's open question,
// docs/performance-notes.md "Session 30"); fluid_flow.cl's end turns contraction back on.
#ifdef FLUID_NO_CONTRACT
#pragma OPENCL FP_CONTRACT OFF
#endif
// The fluid's state laws and the segments' geometry, pure functions of their arguments:
// the liquid's p = K_f max(V₀/V - 1, 0) and its stored energy, the mid-step room, and with
// GAS the polytropic gas's pressure, energy and enthalpy, its smooth aperture and the open
// area between a segment's half faces (cl_kernels/fluid_flow.cl's header has the method).
// Built ahead of cl_kernels/fluid_flow.cl (FluidFlow builds that stage with this library),
// after the stage's defines (GAS, GAS_P0, GAS_GAMMA, FLUID_MODULUS).

inline real fluid_excess(const real v0, const real v) { return v > (real)0 ? fmax(v0 / v - (real)1, (real)0) : (real)0; }
inline real fluid_stored(const real bulk, const real v, const real d) {
  return bulk * v * (((real)1 + d) * log1p(d) - d);
}
// The room predicted for the middle of the step, V + ½ ΔV_last (vertex_rate: the last
// step's change), bounded to ±V/4: the faces' forces and their booked work take the
// pressure at it, so the fluid–solid staggering is second order in the step (with the
// step-start pressure the liquid's faces lagged a step: the KGD start's energy error
// grew with Δt). The bound: a room that closed fast in the last step would otherwise be
// extrapolated to nothing and its fluid to any pressure (a blast's closing cracks did,
// and the run blew up).
inline real mid_step_volume(const real v, const real rate) {
  return v + clamp((real)0.5 * rate, (real)-0.25 * v, (real)0.25 * v);
}
#if !GAS
// The liquid's pressure on the faces over the step: at the mid-step room, or the state's
// own p where no change is predicted (rate 0: a held-pressure source vertex, refilled to
// its p in every sub-step whatever its room, so its p is the held one all step, and the
// account closes exactly with it: p_s ΔV = H(p_s) ΔV₀ - ΔU).
inline real liquid_face_pressure(const real4 s, const real rate) {
  return rate == (real)0 ? s.z : (real)FLUID_MODULUS * fluid_excess(s.x, mid_step_volume(s.y, rate));
}
#endif
#if GAS
// The law stops at p0: gas denser than ρ0 (V₀ > V) holds p0 (a plateau; the products
// are never squeezed above their initial pressure: a blast's crack closing on its gas
// took it to 300 GPa, a spring no explicit step could follow). Its energy stays the
// potential of its pressure, ∂U/∂V = -p: p0 V₀/(γ - 1) + p0 (V₀ - V) on the plateau.
// The gas's aperture: w = w_r ln(1 + e^(o/w_r)), o + w_r ln 2 ... o for an open end
// (o ≫ w_r), w_r ln 2 at o = 0, towards 0 in overlap: smooth, so the faces' forces, its
// slope dw/do = 1/(1 + e^(-o/w_r)) times the pressure, have no jump where a face closes
// (a jump there let trapped gas chatter the faces and the account drift).
inline real gas_aperture(const real o, const real wr) {
  const real x = o / wr;
  return x > (real)30 ? o : wr * log1p(exp(x));
}
inline real gas_aperture_slope(const real o, const real wr) {
  const real x = o / wr;
  return x > (real)30 ? (real)1 : (real)1 / ((real)1 + exp(-x));
}
// The gas's room: the area between the faces, of each half of the segment (the quad of
// face 1's and face 2's halves, i-half (x_i, m, m', x_i'), j-half (m, x_j, x_j', m'), m and
// m' the faces' midpoints), positive where the faces are apart: 1/2 cross(p3 - p1, p2 - p0)
// for the quad (p0, p1, p2, p3), a polynomial in the positions whatever the faces' angle.
// (An opening along the chord's normal had a chord of zero length once a face turned
// over: two flying one-triangle fragments of the blasting case's own mesh, faces
// antiparallel, got a couple of 1/|chord| and the run stopped, cases/blasting/README.md.)
// Its gradient, per corner: (1/2 perp(d2), -1/2 perp(d1), -1/2 perp(d2), 1/2 perp(d1)) with
// d1 = p2 - p0, d2 = p3 - p1 and perp(v) = (v.y, -v.x).
inline real open_area(const real2 p0, const real2 p1, const real2 p2, const real2 p3) {
  const real2 d1 = p2 - p0, d2 = p3 - p1;
  return (real)0.5 * (d2.x * d1.y - d2.y * d1.x);
}
inline real2 perp(const real2 v) { return (real2)(v.y, -v.x); }
inline real gas_pressure(const real v0, const real v) {
  if (!(v > (real)0 && v0 > (real)0)) return (real)0;
  return v0 >= v ? (real)GAS_P0 : (real)GAS_P0 * pow(v0 / v, (real)GAS_GAMMA);
}
inline real gas_energy(const real v0, const real v) {
  if (!(v > (real)0 && v0 > (real)0)) return (real)0;
  if (v0 >= v) return (real)GAS_P0 * (v0 / ((real)GAS_GAMMA - (real)1) + (v0 - v));
  return gas_pressure(v0, v) * v / ((real)GAS_GAMMA - (real)1);
}
inline real gas_enthalpy(const real p) {
  return (real)GAS_GAMMA / ((real)GAS_GAMMA - (real)1) * (real)GAS_P0 *
         pow(p / (real)GAS_P0, ((real)GAS_GAMMA - (real)1) / (real)GAS_GAMMA);
}
#endif
