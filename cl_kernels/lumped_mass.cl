// Lumped mass, once at set-up.
// triangle_mass: one work-item per triangle: each corner a gets (ρ A₀ t / 3, k_a) where
// k_a is the larger of the absolute row sums of the triangle's small-strain stiffness
// matrix in the rows of node a, K_ab = A₀ t B_aᵀ C B_b (C the material's Voigt
// stiffness; Neo-Hookean uses its small-strain limit λ, μ). The node gather sums them
// into (mass, Σk) per node: Σk bounds the assembled stiffness's row sums (Gershgorin).
// With HETEROGENEOUS_YOUNG the row sums take the triangle's factor on E (as the forces do).
// node_inertia: one work-item per node: the inertia used by the integrator, either the
// true mass or, with mass scaling (Eq. 18), 0.3 Δt² Σk, so that ω²_max ≤ Σk/m and
// ω_max Δt ≤ 1/√0.3 ≈ 1.83 < 2: any Δt is stable. (½ Δt² Σk, the textbook choice,
// leaves ω_max Δt ≤ √2 and relaxes about 30% slower; 0.3 reaches the paper's 6,400-step
// geostatic convergence on its 98k-triangle mesh, ½ does not.)

// |B_aᵀ C B_b| row sums of node a, for rows x (.x) and y (.y); B_a on (xx, yy, 2xy).
inline real2 block_row_sums(real2 ga, real2 gb, __global const real* m) {
  const real c11 = m[MAT_C11], c12 = m[MAT_C12], c16 = m[MAT_C16];
  const real c22 = m[MAT_C22], c26 = m[MAT_C26], c66 = m[MAT_C66];
  // C B_b columns: strain of a unit x or y displacement of node b
  const real3 cbx = (real3)(c11 * gb.x + c16 * gb.y, c12 * gb.x + c26 * gb.y, c16 * gb.x + c66 * gb.y);
  const real3 cby = (real3)(c12 * gb.y + c16 * gb.x, c22 * gb.y + c26 * gb.x, c26 * gb.y + c66 * gb.x);
  // rows of B_aᵀ: x → (ga.x, 0, ga.y), y → (0, ga.y, ga.x)
  const real kxx = ga.x * cbx.x + ga.y * cbx.z, kxy = ga.x * cby.x + ga.y * cby.z;
  const real kyx = ga.y * cbx.y + ga.x * cbx.z, kyy = ga.y * cby.y + ga.x * cby.z;
  return (real2)(fabs(kxx) + fabs(kxy), fabs(kyx) + fabs(kyy));
}

__kernel void triangle_mass(const uint n_triangles,
                            __global const uint* restrict tri_nodes,
                            __global const uint* restrict tri_material,
                            __global const real* restrict materials,
                            __global const real2* restrict ref_position,
                            __global const real4* restrict ref_inverse,
                            const real thickness,
                            __global real2* restrict corner_mass
#ifdef HETEROGENEOUS_YOUNG
                            , __global const real* restrict young_factor, const uint young_first,
                            const uint young_count
#endif
                            ) {
  const uint t = get_global_id(0);
  if (t >= n_triangles) return;
  const real2 x0 = ref_position[tri_nodes[3 * t]];
  const real2 x1 = ref_position[tri_nodes[3 * t + 1]];
  const real2 x2 = ref_position[tri_nodes[3 * t + 2]];
  const real2 e1 = x1 - x0, e2 = x2 - x0;
  const real area = (real)0.5 * (e1.x * e2.y - e1.y * e2.x);
  __global const real* m = materials + MATERIAL_STRIDE * tri_material[t];
  const real mass = m[MAT_DENSITY] * area * thickness / (real)3;
  const real4 Xinv = ref_inverse[t];
  real2 g[3];
  g[1] = (real2)(Xinv.x, Xinv.y);
  g[2] = (real2)(Xinv.z, Xinv.w);
  g[0] = -(g[1] + g[2]);
  for (int a = 0; a < 3; ++a) {
    real2 rows = (real2)(0, 0);
    for (int b = 0; b < 3; ++b) rows += block_row_sums(g[a], g[b], m);
#ifdef HETEROGENEOUS_YOUNG  // the triangle's own E (triangle_forces.cl)
    if (t - young_first < young_count) rows *= young_factor[t - young_first];
#endif
    corner_mass[3 * t + a] = (real2)(mass, area * thickness * fmax(rows.x, rows.y));
  }
}

// node_sums: (mass, Σk) per node; node_mass out: with MASS_SCALING 1 (mass, inertia),
// with 0 the mass alone (the inertia is the mass: one real per node). One work-item per
// node. With CE4_STIFFNESS (a define from the host, 0 or 1), extra_stiffness is the CE4s'
// share of Σk, computed on the host (LumpedMass).
__kernel void node_inertia(const uint n_nodes, const real dt, __global const real2* restrict node_sums,
#if MASS_SCALING
                           __global real2* restrict node_mass
#else
                           __global real* restrict node_mass
#endif
#if CE4_STIFFNESS
                           , __global const real* restrict extra_stiffness
#endif
                           ) {
  const uint i = get_global_id(0);
  if (i >= n_nodes) return;
  const real2 mk = node_sums[i];
#if MASS_SCALING
#if CE4_STIFFNESS
  const real k = mk.y + extra_stiffness[i];
#else
  const real k = mk.y;
#endif
  node_mass[i] = (real2)(mk.x, (real)0.3 * dt * dt * k);
#else
  node_mass[i] = mk.x;
#endif
}
