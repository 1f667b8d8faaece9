// Lumped mass, once at set-up.
// triangle_mass: one work-item per triangle: each corner gets (ρ A₀ t / 3, k) where k
// is a Gershgorin-style upper bound of the triangle's stiffness seen by a node,
// k = t · Cmax · p² / (2 A₀) (p perimeter, Cmax the material's stiffness bound). The
// node gather sums them into (mass, Σk) per node.
// node_inertia: one work-item per node: the inertia used by the integrator, either the
// true mass or, with mass scaling (Eq. 18), ½ Δt² Σk, which keeps Δt stable whatever
// its size (ω²_max ≤ Σk/m = 2/Δt²).
__kernel void triangle_mass(const uint n_triangles,
                            __global const uint* restrict tri_nodes,
                            __global const uint* restrict tri_material,
                            __global const real* restrict materials,
                            __global const real2* restrict ref_position,
                            const real thickness,
                            __global real2* restrict corner_mass) {
  const uint t = get_global_id(0);
  if (t >= n_triangles) return;
  const real2 x0 = ref_position[tri_nodes[3 * t]];
  const real2 x1 = ref_position[tri_nodes[3 * t + 1]];
  const real2 x2 = ref_position[tri_nodes[3 * t + 2]];
  const real2 e1 = x1 - x0, e2 = x2 - x0;
  const real area = (real)0.5 * (e1.x * e2.y - e1.y * e2.x);
  const real perimeter = length(e1) + length(e2) + length(x2 - x1);
  __global const real* m = materials + MATERIAL_STRIDE * tri_material[t];
  const real mass = m[MAT_DENSITY] * area * thickness / (real)3;
  const real k = thickness * m[MAT_STIFFNESS_BOUND] * perimeter * perimeter / ((real)2 * area);
  corner_mass[3 * t] = corner_mass[3 * t + 1] = corner_mass[3 * t + 2] = (real2)(mass, k);
}

// node_mass in: (mass, Σk); out: (mass, inertia).
__kernel void node_inertia(const uint n_nodes, const int mass_scaling, const real dt,
                           __global real2* restrict node_mass) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  const real2 mk = node_mass[i];
  node_mass[i] = (real2)(mk.x, mass_scaling ? (real)0.5 * dt * dt * mk.y : mk.x);
}
