// Contact detection (paper Section 2.2, Figs. 6-7): a uniform grid of square cells at
// least as large as the largest triangle's bounding box, rebuilt every run around where
// the bodies are now. Each triangle is hashed to the cell of its box centre; the (hash,
// triangle) list is sorted on the device (Boost.Compute, host side); a cell's first and
// last position in the sorted list are found by comparing neighbours; every triangle then
// scans the 3x3 cells around its own and records the couples (i < j) whose boxes overlap
// and which share no node. Couples are keys (ulong(i) << 32 | j), appended through a
// 32-bit atomic counter and sorted on the host side afterwards, so the list is canonical.
//
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).
// Lengths are in metres; a box is real4 (min x, min y, max x, max y).

#define EMPTY_CELL 0xffffffffu

#ifdef FDEM_DOUBLE
#define REAL_EPS 2.220446049250313e-16
#else
#define REAL_EPS 1.1920929e-7f
#endif

// Cell (ix, iy) of a box's centre, clamped into the grid.
// g = (x0, y0, cell size, unused), dims = (nx, ny, nx*ny, unused).
inline int2 cell_of(real4 box, real4 g, uint4 dims) {
  const real cx = (real)0.5 * (box.x + box.z);
  const real cy = (real)0.5 * (box.y + box.w);
  const real fx = floor((cx - g.x) / g.z);
  const real fy = floor((cy - g.y) / g.z);
  // Clamp in real before converting (out-of-range conversions are undefined); fmax
  // returns its other operand for a NaN, so a non-finite centre lands in cell 0.
  const int ix = (int)fmin(fmax(fx, (real)0), (real)(dims.x - 1));
  const int iy = (int)fmin(fmax(fy, (real)0), (real)(dims.y - 1));
  return (int2)(ix, iy);
}

inline bool boxes_overlap(real4 a, real4 b) {
  return a.x <= b.z && b.x <= a.z && a.y <= b.w && b.y <= a.w;
}

// One work-item per triangle t: its current bounding box grown by half_skin on every
// side, and the work-group's share of the global reduction (lowest corner, highest
// corner, largest box side).
// Inputs: node positions [m], tri_nodes (3 per triangle), half_skin [m].
// Outputs: boxes[t] [m]; per work-group g: partial_bounds[g] = (min x, min y, max x,
// max y) of its boxes [m], partial_side[g] = its largest box side [m].
__kernel void triangle_boxes(const uint n_triangles,
                             __global const uint* restrict tri_nodes,
                             __global const real2* restrict position,
                             const real half_skin,
                             __global real4* restrict boxes,
                             __global real4* restrict partial_bounds,
                             __global real* restrict partial_side) {
  __local real4 scratch[GROUP_SIZE];
  const uint t = get_global_id(0);
  const uint lid = get_local_id(0);
  real4 mine = (real4)((real)INFINITY, (real)INFINITY, -(real)INFINITY, -(real)INFINITY);
  real my_side = 0;
  if (t < n_triangles) {
    const real2 a = position[tri_nodes[3 * t]];
    const real2 b = position[tri_nodes[3 * t + 1]];
    const real2 c = position[tri_nodes[3 * t + 2]];
    mine = (real4)(fmin(fmin(a.x, b.x), c.x) - half_skin, fmin(fmin(a.y, b.y), c.y) - half_skin,
                   fmax(fmax(a.x, b.x), c.x) + half_skin, fmax(fmax(a.y, b.y), c.y) + half_skin);
    boxes[t] = mine;
    my_side = fmax(mine.z - mine.x, mine.w - mine.y);
  }
  // Lowest corner as the maximum of the negated one.
  const real4 folded = group_max4(scratch, (real4)(-mine.x, -mine.y, mine.z, mine.w));
  barrier(CLK_LOCAL_MEM_FENCE);  // work-item 0 has read the fold before scratch is reused
  const real largest = group_max4(scratch, (real4)(my_side, 0, 0, 0)).x;
  if (lid == 0) {
    partial_bounds[get_group_id(0)] = (real4)(-folded.x, -folded.y, folded.z, folded.w);
    partial_side[get_group_id(0)] = largest;
  }
}

// Launched as ONE work-group of GROUP_SIZE work-items. Work-item l folds the partials
// l, l + GROUP_SIZE, ...; the group reduces them; work-item 0 then writes the grid:
// origin = lowest box corner, cell = largest box side (plus a rounding margin, so that
// two overlapping boxes always have centres in the same or adjacent cells), nx, ny so
// the cells cover the highest box corner. When nx*ny would exceed max_cells the cell
// grows until it fits (correct for any cell >= the largest box side).
// Inputs: n_groups partials from triangle_boxes [m]. Outputs: grid = (x0, y0, cell,
// largest box side) [m]; dims = (nx, ny, nx*ny, 0).
__kernel void grid_setup(const uint n_groups,
                         __global const real4* restrict partial_bounds,
                         __global const real* restrict partial_side,
                         const uint max_cells,
                         __global real4* restrict grid,
                         __global uint4* restrict dims) {
  __local real4 scratch[GROUP_SIZE];
  const uint lid = get_local_id(0);
  real4 mine = (real4)((real)INFINITY, (real)INFINITY, -(real)INFINITY, -(real)INFINITY);
  real my_side = 0;
  for (uint g = lid; g < n_groups; g += GROUP_SIZE) {
    const real4 o = partial_bounds[g];
    mine = (real4)(fmin(mine.x, o.x), fmin(mine.y, o.y), fmax(mine.z, o.z), fmax(mine.w, o.w));
    my_side = fmax(my_side, partial_side[g]);
  }
  const real4 folded = group_max4(scratch, (real4)(-mine.x, -mine.y, mine.z, mine.w));
  barrier(CLK_LOCAL_MEM_FENCE);  // work-item 0 has read the fold before scratch is reused
  const real largest = group_max4(scratch, (real4)(my_side, 0, 0, 0)).x;
  if (lid != 0) return;

  const real4 b = (real4)(-folded.x, -folded.y, folded.z, folded.w);
  const real width = b.z - b.x, height = b.w - b.y;
  const real magnitude = fmax(fmax(fabs(b.x), fabs(b.y)), fmax(fabs(b.z), fabs(b.w)));
  real cell = largest * (real)1.015625 + (real)16 * REAL_EPS * magnitude;
  if (!(cell > (real)0) || !isfinite(cell)) cell = fmax(fmax(width, height), (real)1);
  real nx = floor(width / cell) + (real)1, ny = floor(height / cell) + (real)1;
  if (nx * ny > (real)max_cells) {
    // Start near the size that fits (cell² ≈ area / max_cells), then grow in small steps.
    cell = fmax(cell, sqrt(width * height / (real)max_cells));
    for (int k = 0; k < 4096; ++k) {
      nx = floor(width / cell) + (real)1;
      ny = floor(height / cell) + (real)1;
      if (nx * ny <= (real)max_cells) break;
      cell *= (real)1.0625;
    }
  }
  // Non-finite bounds (a NaN or infinite node) leave nx, ny meaningless: one cell then.
  if (!(nx * ny <= (real)max_cells)) nx = ny = (real)1;
  const uint unx = (uint)nx, uny = (uint)ny;
  grid[0] = (real4)(b.x, b.y, cell, largest);
  dims[0] = (uint4)(unx, uny, unx * uny, 0);
}

// One work-item per cell c < max_cells: marks the cell empty.
// Outputs: cell_first[c] = cell_last[c] = EMPTY_CELL.
__kernel void clear_cells(const uint max_cells,
                          __global uint* restrict cell_first,
                          __global uint* restrict cell_last) {
  const uint c = get_global_id(0);
  if (c >= max_cells) return;
  cell_first[c] = EMPTY_CELL;
  cell_last[c] = EMPTY_CELL;
}

// One work-item per triangle t: the hash iy*nx + ix of the cell holding its box centre.
// Inputs: boxes [m], the grid. Outputs: hash[t], and tri[t] = t (the value the sort
// carries along).
__kernel void cell_hash(const uint n_triangles,
                        __global const real4* restrict boxes,
                        __global const real4* restrict grid,
                        __global const uint4* restrict dims,
                        __global uint* restrict hash,
                        __global uint* restrict tri) {
  const uint t = get_global_id(0);
  if (t >= n_triangles) return;
  const uint4 d = dims[0];
  const int2 c = cell_of(boxes[t], grid[0], d);
  hash[t] = (uint)c.y * d.x + (uint)c.x;
  tri[t] = t;
}

// One work-item per position k of the hash list sorted ascending: if k starts a run of
// equal hashes it writes cell_first[hash] = k, if it ends one cell_last[hash] = k
// (inclusive). Cells no triangle hashed to keep EMPTY_CELL from clear_cells.
__kernel void cell_range(const uint n_triangles,
                         __global const uint* restrict sorted_hash,
                         __global uint* restrict cell_first,
                         __global uint* restrict cell_last) {
  const uint k = get_global_id(0);
  if (k >= n_triangles) return;
  const uint h = sorted_hash[k];
  if (k == 0 || sorted_hash[k - 1] != h) cell_first[h] = k;
  if (k == n_triangles - 1 || sorted_hash[k + 1] != h) cell_last[h] = k;
}

// One work-item per triangle i: scans the 3x3 cells around the cell of its box centre;
// for every triangle j > i listed there that is a candidate with i, whose box overlaps i's
// and that shares no node with i, it appends the key (ulong(i) << 32 | j). Candidates:
// i and j both active, or (with BONDED_PAIRS, activation "fractured") j is one of the up
// to three triangles a CE4 joins to i (bond_partners[3i..3i+2], NO_PARTNER where none).
// Bonded couples take part from the start, active or not: their faces touch along the
// CE4 and may overlap under compression; a couple switched on only when its CE4 breaks
// would start with that overlap's contact energy, which no force supplied (issue 11). The slot comes from a
// 32-bit atomic counter; past `capacity` nothing is written but the counter still counts,
// so the host learns the exact size needed and reruns.
// Inputs: tri_nodes, boxes [m], active (nonzero = takes part), the grid, cell ranges,
// sorted triangle list. Outputs: keys[0 .. capacity), count[0] = number of couples.
__kernel void find_couples(const uint n_triangles,
                           __global const uint* restrict tri_nodes,
                           __global const real4* restrict boxes,
                           __global const uint* restrict active,
                           __global const real4* restrict grid,
                           __global const uint4* restrict dims,
                           __global const uint* restrict cell_first,
                           __global const uint* restrict cell_last,
                           __global const uint* restrict sorted_tri,
                           const uint capacity,
                           volatile __global uint* count,
                           __global ulong* restrict keys
#ifdef BONDED_PAIRS
                           , __global const uint* restrict bond_partners
#endif
#ifdef OWNED_FIRST
                           , __global const uchar* restrict owned_first
#endif
                           ) {
  const uint i = get_global_id(0);
  if (i >= n_triangles) return;
#ifdef OWNED_FIRST
  // A split run: this rank lists only the couples whose lower triangle it owns.
  if (owned_first[i] == 0) return;
#endif
#ifdef BONDED_PAIRS
  const uint p0 = bond_partners[3 * i], p1 = bond_partners[3 * i + 1], p2 = bond_partners[3 * i + 2];
  const bool i_active = active[i] != 0;
  if (!i_active && p0 == NO_PARTNER && p1 == NO_PARTNER && p2 == NO_PARTNER) return;
#else
  if (active[i] == 0) return;
#endif
  const uint4 d = dims[0];
  const real4 box = boxes[i];
  const int2 c = cell_of(box, grid[0], d);
  const uint a0 = tri_nodes[3 * i], a1 = tri_nodes[3 * i + 1], a2 = tri_nodes[3 * i + 2];
  const int y_lo = max(c.y - 1, 0), y_hi = min(c.y + 1, (int)d.y - 1);
  const int x_lo = max(c.x - 1, 0), x_hi = min(c.x + 1, (int)d.x - 1);
  for (int cy = y_lo; cy <= y_hi; ++cy) {
    for (int cx = x_lo; cx <= x_hi; ++cx) {
      const uint h = (uint)cy * d.x + (uint)cx;
      const uint first = cell_first[h];
      if (first == EMPTY_CELL) continue;
      const uint last = cell_last[h];
      for (uint k = first; k <= last; ++k) {
        const uint j = sorted_tri[k];
#ifdef BONDED_PAIRS
        if (j <= i || !((i_active && active[j] != 0) || j == p0 || j == p1 || j == p2)) continue;
#else
        if (j <= i || active[j] == 0) continue;
#endif
        if (!boxes_overlap(box, boxes[j])) continue;
        const uint b0 = tri_nodes[3 * j], b1 = tri_nodes[3 * j + 1], b2 = tri_nodes[3 * j + 2];
        if (a0 == b0 || a0 == b1 || a0 == b2 || a1 == b0 || a1 == b1 || a1 == b2 ||
            a2 == b0 || a2 == b1 || a2 == b2)
          continue;
        const uint slot = atomic_inc(count);
        if (slot < capacity) keys[slot] = ((ulong)i << 32) | (ulong)j;
      }
    }
  }
}

// Bitonic sort of buf[0 .. p) ascending (p a power of two), by the whole work-group.
inline void bitonic_sort_local(__local ulong* buf, const uint p) {
  const uint lid = get_local_id(0);
  for (uint k = 2; k <= p; k <<= 1) {
    for (uint j = k >> 1; j > 0; j >>= 1) {
      for (uint i = lid; i < p; i += GROUP_SIZE) {
        const uint l = i ^ j;
        if (l > i) {
          const ulong a = buf[i], b = buf[l];
          const bool ascending = (i & k) == 0;
          if ((a > b) == ascending) {
            buf[i] = b;
            buf[l] = a;
          }
        }
      }
      barrier(CLK_LOCAL_MEM_FENCE);
    }
  }
}

// Smallest power of two >= n (n <= SMALL_SORT).
inline uint sort_width(const uint n) {
  uint p = 1;
  while (p < n) p <<= 1;
  return p;
}

// Launched as ONE work-group (small models: n <= SMALL_SORT, a power of two). Sorts the
// (hash, triangle) pairs by hash, ties by triangle (so the order a stable sort of the
// hashes gives, the triangles being in order before): each pair as one ulong
// hash << 32 | triangle in local memory, a bitonic network, written back. One launch
// instead of a library sort's many (a small model's detection is launch-bound).
__kernel void sort_small_pairs(const uint n, __global uint* restrict hash, __global uint* restrict tri) {
  __local ulong buf[SMALL_SORT];
  const uint p = sort_width(n);
  for (uint i = get_local_id(0); i < p; i += GROUP_SIZE)
    buf[i] = i < n ? ((ulong)hash[i] << 32) | (ulong)tri[i] : (ulong)0xffffffffffffffffUL;
  barrier(CLK_LOCAL_MEM_FENCE);
  bitonic_sort_local(buf, p);
  for (uint i = get_local_id(0); i < n; i += GROUP_SIZE) {
    hash[i] = (uint)(buf[i] >> 32);
    tri[i] = (uint)(buf[i] & 0xffffffffUL);
  }
}

// Launched as ONE work-group (n <= SMALL_SORT): sorts the couple keys keys[0 .. n)
// ascending in local memory (bitonic network; the keys are unique, so the order is the
// one any sort gives).
__kernel void sort_small_keys(const uint n, __global ulong* restrict keys) {
  __local ulong buf[SMALL_SORT];
  const uint p = sort_width(n);
  for (uint i = get_local_id(0); i < p; i += GROUP_SIZE) buf[i] = i < n ? keys[i] : (ulong)0xffffffffffffffffUL;
  barrier(CLK_LOCAL_MEM_FENCE);
  bitonic_sort_local(buf, p);
  for (uint i = get_local_id(0); i < n; i += GROUP_SIZE) keys[i] = buf[i];
}
