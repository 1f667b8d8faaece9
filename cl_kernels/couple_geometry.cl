// The geometry of a contact couple (two triangles c and t): the potential integrals along
// each edge pass, the couple potential and the overlap area, the barycentric values of
// each triangle's vertices in the other, the cheap separation test. Pure functions of
// the six corner positions, no memory but what they are given; included ahead of
// cl_kernels/contact_forces.cl (ContactForces builds that stage with this library).

// Compare-exchange: a ≤ b afterwards.
#define SORT2(a, b)           \
  {                           \
    const real lo = fmin(a, b); \
    b = fmax(a, b);           \
    a = lo;                   \
  }

// ∫ g(s) ds split into I0 = ∫(1−s) g, I1 = ∫ s g over s in [0, 1], g = max(0, min_m l_m(s)),
// l_m(s) = l0[m] + s (l1[m] − l0[m]); also the length fraction where g > 0.
// g is linear between its kinks: where some l_m = 0 and where two l_m cross. The six
// candidates (those outside (0, 1) moved to 1, where they only add pieces of zero width,
// which add exact zeros) are ordered by a fixed sorting network, so everything stays in
// registers; the trapezoid rule is then exact on each piece.
// A piece counts as inside when the potential at its middle exceeds `round_off`, the
// rounding of l itself: an edge lying on the other triangle's edge (two faces of an intact
// CE4, which the split mesh puts on the same line) then counts on neither side, as it
// does exactly, instead of on one side only by the sign of a rounding error. The area of
// the overlap (couple_potential) is a sum over both triangles' inside pieces, and one
// coincident edge counted alone adds a third of a triangle's area to it.
inline void integrate_potential(const real l0[3], const real l1[3], const real round_off, real* I0, real* I1,
                                real* inside) {
  // An edge wholly on the outer side of one of the other triangle's edge lines (both ends
  // l_m ≤ 0) has g ≡ 0: the general path below would add exact zeros. Most passes of a
  // couple whose overlap is a sliver (the faces of a CE4 under compression) are such.
  if ((l0[0] <= (real)0 && l1[0] <= (real)0) || (l0[1] <= (real)0 && l1[1] <= (real)0) ||
      (l0[2] <= (real)0 && l1[2] <= (real)0)) {
    *I0 = *I1 = *inside = (real)0;
    return;
  }
  real z[6];
  for (int m = 0; m < 3; ++m) {
    const real d = l1[m] - l0[m];
    const real root = d != (real)0 ? -l0[m] / d : (real)1;  // l_m = 0
    z[m] = root > (real)0 && root < (real)1 ? root : (real)1;
  }
  for (int m = 0, q = 3; m < 3; ++m)
    for (int k = m + 1; k < 3; ++k, ++q) {  // l_m = l_k
      const real dd = (l1[m] - l0[m]) - (l1[k] - l0[k]);
      const real cross = dd != (real)0 ? (l0[k] - l0[m]) / dd : (real)1;
      z[q] = cross > (real)0 && cross < (real)1 ? cross : (real)1;
    }
  // Optimal 12-comparator network for six values.
  SORT2(z[0], z[5]) SORT2(z[1], z[3]) SORT2(z[2], z[4])
  SORT2(z[1], z[2]) SORT2(z[3], z[4])
  SORT2(z[0], z[3]) SORT2(z[2], z[5])
  SORT2(z[0], z[1]) SORT2(z[2], z[3]) SORT2(z[4], z[5])
  SORT2(z[1], z[2]) SORT2(z[3], z[4])
  real i_all = 0, i_s = 0, length = 0;
  real prev_s = (real)0;
  real prev_g = fmax((real)0, fmin(l0[0], fmin(l0[1], l0[2])));
  for (int a = 0; a < 7; ++a) {
    const real t = a < 6 ? z[a] : (real)1;
    const real g = fmax((real)0, fmin(l0[0] + t * (l1[0] - l0[0]), fmin(l0[1] + t * (l1[1] - l0[1]), l0[2] + t * (l1[2] - l0[2]))));
    const real w = t - prev_s;
    i_all += w * (real)0.5 * (prev_g + g);
    i_s += w * (prev_g * ((real)2 * prev_s + t) + g * (prev_s + (real)2 * t)) / (real)6;
    // inside the other triangle on this piece: the potential's minimum at its middle is ≥ 0
    const real mid = (real)0.5 * (prev_s + t);
    const real gm = fmin(l0[0] + mid * (l1[0] - l0[0]), fmin(l0[1] + mid * (l1[1] - l0[1]), l0[2] + mid * (l1[2] - l0[2])));
    if (gm > round_off) length += w;
    prev_s = t;
    prev_g = g;
  }
  *I1 = i_s;
  *I0 = i_all - i_s;
  *inside = length;
}

// The potential of a couple: potential[k] = ∫_{c∩t} φ_k dA for its triangles k = 0, 1;
// E = P_n t (potential[0] + potential[1]). For a translation of c against t, dE is
// −f_c · dx exactly (the boundary term of the moving domain is P_n t ∫_{∂c∩t} φ_t n ds, the
// edge passes' integral). For general node motion the edge passes give the lever-rule
// part of ∂E/∂x exactly, but the barycentric reaction misses one term: φ_t at a fixed
// point changes when t's nodes move, ∂φ_t/∂y_i = −λ_i ∇φ_t, and ∫ λ_i ∇φ_t dA differs
// from the boundary form by −∇λ_i ∫_Ω φ_t dA = −(∫_Ω φ_t dA / A_t) ∂A_t/∂y_i. That area term
// (zero net force and moment) is added to each triangle's nodes in contact_forces; with
// it the forces are −∂E/∂x (tested to 1e-7 by finite differences). Computed from the
// edge passes' integrals: in each centroid sub-triangle of t, φ_t
// is linear and 1 at t's centroid g, so div((x − g) φ_t) = 3 φ_t − 1 there, and (x − g) φ_t
// is continuous and zero on t's boundary. The divergence theorem over Ω = c∩t then gives
//   ∫_Ω φ_t dA = (∫_{∂c∩t} φ_t (x − g)·n ds + |Ω|) / 3,
// and (x − g)·n is constant along a straight edge, so each pass adds (a − g)·n L × I
// (a: the edge's first vertex, I: its ∫φ ds / L). |Ω| = ½ ∮ (x − r)·n ds over the edge
// parts inside the other triangle, again one constant per pass times the inside fraction.
// Area of c ∩ t (triangles 0 and 1, counter-clockwise) by clipping triangle 0 against
// triangle 1's three edges (Sutherland-Hodgman; at most six vertices). Unlike a sum over
// the inside pieces of both triangles' edges, which counts an edge lying on the other's
// edge (the faces of an intact CE4 are on one line) on one side or the other by the sign
// of a rounding error, the clipped polygon's area goes to 0 continuously as a sliver thins.
inline real overlap_area(real2 x[2][3]) {
  real2 poly[9], next[9];
  int n = 3;
  for (int a = 0; a < 3; ++a) poly[a] = x[0][a] - x[1][0];  // relative to one vertex: fewer digits lost
  for (int m = 0; m < 3; ++m) {
    const real2 w = x[1][m] - x[1][0], edge = x[1][(m + 1) % 3] - x[1][m];
    int k = 0;
    for (int i = 0; i < n; ++i) {
      const real2 p = poly[i], q = poly[(i + 1) % n];
      const real sp = edge.x * (p.y - w.y) - edge.y * (p.x - w.x);
      const real sq = edge.x * (q.y - w.y) - edge.y * (q.x - w.x);
      if (sp >= (real)0) next[k++] = p;
      if ((sp >= (real)0) != (sq >= (real)0)) next[k++] = p + (q - p) * (sp / (sp - sq));
    }
    n = k;
    for (int i = 0; i < n; ++i) poly[i] = next[i];
  }
  real twice = (real)0;
  for (int i = 1; i + 1 < n; ++i) {
    const real2 u = poly[i] - poly[0], v = poly[i + 1] - poly[0];
    twice += u.x * v.y - u.y * v.x;
  }
  return fmax((real)0.5 * twice, (real)0);
}

// The same with the overlap's area given (overlap_area(x), which contact_forces_lanes
// works out beside the edge passes).
inline void couple_potential_of_area(real2 x[2][3], const real I0[6], const real I1[6], const real area,
                                     real potential[2]) {
  real2 g[2];
  for (int k = 0; k < 2; ++k) g[k] = (x[k][0] + x[k][1] + x[k][2]) / (real)3;
  real flux[2] = {0, 0};
  for (int dir = 0; dir < 2; ++dir)
    for (int e = 0; e < 3; ++e) {
      const int p = 3 * dir + e;
      const real2 pa = x[dir][e], edge = x[dir][(e + 1) % 3] - pa;
      const real2 nL = (real2)(edge.y, -edge.x);
      flux[1 - dir] += dot(pa - g[1 - dir], nL) * (I0[p] + I1[p]);  // A = dir's edges in φ of B = 1 − dir
    }
  // ∫_Ω φ_k dA for k = 0, 1.
  for (int k = 0; k < 2; ++k) potential[k] = (flux[k] + area) / (real)3;
}

inline void couple_potential(real2 x[2][3], const real I0[6], const real I1[6], const real inside[6], real potential[2]) {
  couple_potential_of_area(x, I0, I1, overlap_area(x), potential);
}

// The couple's two triangles (i, j from its key): node indices and positions.
inline void couple_nodes(const ulong key, __global const uint* tri_nodes, __global const real2* position,
                         uint tri[2], uint nodes[2][3], real2 x[2][3]) {
  tri[0] = (uint)(key >> 32);
  tri[1] = (uint)(key & 0xffffffffUL);
  for (int k = 0; k < 2; ++k)
    for (int a = 0; a < 3; ++a) {
      nodes[k][a] = tri_nodes[3 * tri[k] + a];
      x[k][a] = position[nodes[k][a]];
    }
}

// lv[dir][a][m]: three times the barycentric weight, in triangle B = 1 − dir, of the
// vertex opposite B's edge m, at vertex a of triangle dir (l_m = 3 A_m / A; negative
// outside edge m).
inline void barycentric_values(real2 x[2][3], real lv[2][3][3]) {
  for (int dir = 0; dir < 2; ++dir) {
    const int B = 1 - dir;
    const real2 w0 = x[B][0], w1 = x[B][1], w2 = x[B][2];
    const real twice_area = (w1.x - w0.x) * (w2.y - w0.y) - (w1.y - w0.y) * (w2.x - w0.x);
    const real three_over_area = (real)3 / twice_area;  // one division, not nine
    for (int m = 0; m < 3; ++m) {
      const real2 wm = x[B][m], wn = x[B][(m + 1) % 3];
      const real2 edge = wn - wm;
      for (int a = 0; a < 3; ++a) {
        const real2 p = x[dir][a];
        lv[dir][a][m] = (edge.x * (p.y - wm.y) - edge.y * (p.x - wm.x)) * three_over_area;
      }
    }
  }
}

// Whether one triangle's three vertices all lie on or outside one edge line of the
// other: that line separates them, so they do not overlap. The same cross products as
// barycentric_values, by sign only (no division): where this says separated, every
// l_m there is ≤ 0 as well.
inline bool separated(real2 x[2][3]) {
  bool apart = false;
  for (int dir = 0; dir < 2; ++dir) {
    const int B = 1 - dir;
    const real2 w0 = x[B][0], w1 = x[B][1], w2 = x[B][2];
    const real twice_area = (w1.x - w0.x) * (w2.y - w0.y) - (w1.y - w0.y) * (w2.x - w0.x);
    for (int m = 0; m < 3; ++m) {
      const real2 wm = x[B][m], wn = x[B][(m + 1) % 3];
      const real2 edge = wn - wm;
      bool outside = true;
      for (int a = 0; a < 3; ++a) {
        const real2 p = x[dir][a];
        outside = outside && !((edge.x * (p.y - wm.y) - edge.y * (p.x - wm.x)) * twice_area > (real)0);
      }
      apart = apart || outside;
    }
  }
  return apart;
}
