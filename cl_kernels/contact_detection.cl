// Contact detection (paper Section 2.2, Figs. 6-7): a uniform grid of square cells,
// rebuilt every run around where the bodies are now, and a counting sort of the
// triangles into it (a count per cell, a prefix sum, a scatter). The cell is as large as
// a "small" triangle's box may be: the geometric mean of the smallest and the largest box
// side (graded meshes: a cell as large as the largest element would hold hundreds of the
// smallest, and one work-item scans them all; one as small as the smallest would enter
// the largest in hundreds of cells). A small triangle is entered in the cell of its box
// centre, a large one in every cell its box covers. Every triangle then looks through
// the cells where a partner's entry must be (the 3x3 cells around a small triangle's
// centre, the cells a large one covers and a ring around them) for the couples (i < j)
// whose boxes overlap and which share no node, twice: once to count them, once (after a
// prefix sum of the counts over the triangles) to write them, each triangle into its own
// segment of the list, sorted there. Couples are keys (ulong(i) << 32 | j); triangle i's
// segment follows triangle i-1's, so the list is in ascending key order, whatever order
// the scatter put a cell's entries in. No sort of the whole list, no allocation; the host
// reads the entry and couple counts once.
//
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).
// Lengths are in metres; a box is real4 (min x, min y, max x, max y).

#ifdef FDEM_DOUBLE
#define REAL_EPS 2.220446049250313e-16
#else
#define REAL_EPS 1.1920929e-7f
#endif

// Column or row of a coordinate, clamped into [0, cells - 1]. Clamped in real before
// converting (out-of-range conversions are undefined); fmax returns its other operand
// for a NaN, so a non-finite coordinate lands in cell 0.
inline int cell_coordinate(const real v, const real origin, const real cell, const uint cells) {
  return (int)fmin(fmax(floor((v - origin) / cell), (real)0), (real)(cells - 1));
}

// The cells where a triangle's entries go, (x0, y0, x1, y1) inclusive: the cell of the
// box centre for a small box (both sides at most g.w), every cell the box covers for a
// large one. g = (x0, y0, cell size, largest small side), dims = (nx, ny, nx*ny, unused).
inline int4 entry_cells(const real4 box, const real4 g, const uint4 d) {
  if (box.z - box.x <= g.w && box.w - box.y <= g.w) {
    const int cx = cell_coordinate((real)0.5 * (box.x + box.z), g.x, g.z, d.x);
    const int cy = cell_coordinate((real)0.5 * (box.y + box.w), g.y, g.z, d.y);
    return (int4)(cx, cy, cx, cy);
  }
  return (int4)(cell_coordinate(box.x, g.x, g.z, d.x), cell_coordinate(box.y, g.y, g.z, d.y),
                cell_coordinate(box.z, g.x, g.z, d.x), cell_coordinate(box.w, g.y, g.z, d.y));
}

// The boxes are kept in float (16 B a triangle instead of 32 in double builds), each
// rounded outward (its low corner down, its high one up: triangle_boxes), so a stored box
// holds the exact one and the couples found are a superset of the exact boxes' (the gap
// rule and the contact stage sort out the few more). Every kernel reads them through
// load_box, and the grid is taken from the stored boxes, so all agree on them.
inline real4 load_box(__global const float4* boxes, const uint t) {
#ifdef FDEM_DOUBLE
  return convert_double4(boxes[t]);
#else
  return boxes[t];
#endif
}

inline bool boxes_overlap(real4 a, real4 b) {
  return a.x <= b.z && b.x <= a.z && a.y <= b.w && b.y <= a.w;
}

// One work-item per triangle t: its current bounding box grown by half_skin on every
// side, and the work-group's share of the global reductions (lowest corner, highest
// corner, largest and smallest box side).
// Inputs: node positions [m], tri_nodes (3 per triangle), half_skin [m].
// Outputs: boxes[t] [m] (float, rounded outward: load_box); per work-group g: partial_bounds[g] = (min x, min y, max x,
// max y) of its boxes [m], partial_side[g] = (its largest box side, minus its smallest)
// [m] (a box's side: the larger of its two).
__kernel void triangle_boxes(const uint n_triangles,
                             __global const uint* restrict tri_nodes,
                             __global const real2* restrict position,
                             const real half_skin,
                             __global float4* restrict boxes,
                             __global real4* restrict partial_bounds,
                             __global real2* restrict partial_side) {
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
#ifdef FDEM_DOUBLE
    const float4 stored = (float4)(convert_float_rtn(mine.x), convert_float_rtn(mine.y), convert_float_rtp(mine.z),
                                   convert_float_rtp(mine.w));
    mine = convert_double4(stored);  // the reductions below take the stored box
#else
    const float4 stored = mine;
#endif
    boxes[t] = stored;
    my_side = fmax(mine.z - mine.x, mine.w - mine.y);
  }
  // Lowest corner as the maximum of the negated one.
  const real4 folded = group_max4(scratch, (real4)(-mine.x, -mine.y, mine.z, mine.w));
  barrier(CLK_LOCAL_MEM_FENCE);  // work-item 0 has read the fold before scratch is reused
  const real2 sides = group_max4(scratch, (real4)(my_side, t < n_triangles ? -my_side : -(real)INFINITY, 0, 0)).xy;
  if (lid == 0) {
    partial_bounds[get_group_id(0)] = (real4)(-folded.x, -folded.y, folded.z, folded.w);
    partial_side[get_group_id(0)] = sides;
  }
}

// Launched as ONE work-group of GROUP_SIZE work-items. Work-item l folds the partials
// l, l + GROUP_SIZE, ... in order; the group reduces them by a fixed tree; work-item 0
// then writes the grid: origin = lowest box corner; the largest small side = the
// geometric mean of the smallest and the largest box side; cell = that side plus a rounding
// margin (so that two overlapping small boxes have centres in the same or adjacent
// cells); nx, ny so the cells cover the highest box corner. When nx*ny would exceed
// max_cells the cell grows until it fits (correct for any cell >= the small side).
// Inputs: n_groups partials from triangle_boxes [m]. Outputs: grid = (x0, y0, cell,
// largest small side) [m]; dims = (nx, ny, nx*ny, 0).
__kernel void grid_setup(const uint n_groups,
                         __global const real4* restrict partial_bounds,
                         __global const real2* restrict partial_side,
                         const uint max_cells,
                         __global real4* restrict grid,
                         __global uint4* restrict dims) {
  __local real4 scratch[GROUP_SIZE];
  const uint lid = get_local_id(0);
  real4 mine = (real4)((real)INFINITY, (real)INFINITY, -(real)INFINITY, -(real)INFINITY);
  real2 my_sides = (real2)(0, -(real)INFINITY);
  for (uint g = lid; g < n_groups; g += GROUP_SIZE) {
    const real4 o = partial_bounds[g];
    mine = (real4)(fmin(mine.x, o.x), fmin(mine.y, o.y), fmax(mine.z, o.z), fmax(mine.w, o.w));
    my_sides = fmax(my_sides, partial_side[g]);
  }
  const real4 folded = group_max4(scratch, (real4)(-mine.x, -mine.y, mine.z, mine.w));
  barrier(CLK_LOCAL_MEM_FENCE);  // work-item 0 has read the fold before scratch is reused
  const real2 sides = group_max4(scratch, (real4)(my_sides, 0, 0)).xy;
  const real largest = sides.x, smallest = -sides.y;
  if (lid != 0) return;

  const real4 b = (real4)(-folded.x, -folded.y, folded.z, folded.w);
  const real width = b.z - b.x, height = b.w - b.y;
  const real magnitude = fmax(fmax(fabs(b.x), fabs(b.y)), fmax(fabs(b.z), fabs(b.w)));
  real small_side = fmin(largest, sqrt(fmax(smallest, (real)0) * largest));
  const real margin = (real)16 * REAL_EPS * magnitude;
  real cell = small_side * (real)1.015625 + margin;
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
  // A cell grown to fit the cap takes the boxes up to its own size as small.
  small_side = fmax(small_side, (cell - margin) / (real)1.015625);
  grid[0] = (real4)(b.x, b.y, cell, isfinite(small_side) ? small_side : cell);
  dims[0] = (uint4)(unx, uny, unx * uny, 0);
}

// Exclusive prefix sum, in place, of data[0 .. n), in three launches: scan_blocks (one
// work-group per block of SCAN_BLOCK = 4 x GROUP_SIZE entries: the block's own prefix sums
// and its total), scan_block_sums (one work-group: the totals' prefix sums), scan_add
// (each entry plus its block's offset). Unsigned integers: exact in any order.

// One work-item per four consecutive entries of a block: the block-local exclusive
// prefix sums of data, and the block's total in block_sums[group].
__kernel void scan_blocks(const uint n, __global uint* restrict data, __global uint* restrict block_sums) {
  __local uint scratch[GROUP_SIZE];
  const uint base = get_group_id(0) * (4 * GROUP_SIZE) + 4 * get_local_id(0);
  uint v[4], sum = 0;
  for (int k = 0; k < 4; ++k) {
    v[k] = base + k < n ? data[base + k] : 0u;
    sum += v[k];
  }
  uint total;
  uint running = group_exclusive_scan(scratch, sum, &total);
  for (int k = 0; k < 4; ++k) {
    if (base + k < n) data[base + k] = running;
    running += v[k];
  }
  if (get_local_id(0) == 0) block_sums[get_group_id(0)] = total;
}

// Launched as ONE work-group: block_sums[0 .. n_blocks) replaced by their exclusive
// prefix sums (work-item l takes a contiguous run of blocks).
__kernel void scan_block_sums(const uint n_blocks, __global uint* restrict block_sums) {
  __local uint scratch[GROUP_SIZE];
  group_scan_global(scratch, block_sums, n_blocks);
}

// One work-item per entry k < n: adds the offset of its block.
__kernel void scan_add(const uint n, __global uint* restrict data, __global const uint* restrict block_sums) {
  const uint k = get_global_id(0);
  if (k < n) data[k] += block_sums[k / (4 * GROUP_SIZE)];
}

// One work-item per triangle t: counts its entries into the cells (entry_cells), at
// cell_start[cell + 1], which must be zero before. The prefix sum over the max_cells + 1
// words then gives in cell_start[c + 1] the start of cell c's entries (cell_start[0] = 0).
__kernel void cell_count(const uint n_triangles,
                         __global const float4* restrict boxes,
                         __global const real4* restrict grid,
                         __global const uint4* restrict dims,
                         volatile __global uint* cell_start) {
  const uint t = get_global_id(0);
  if (t >= n_triangles) return;
  const uint4 d = dims[0];
  const int4 r = entry_cells(load_box(boxes, t), grid[0], d);
  for (int cy = r.y; cy <= r.w; ++cy)
    for (int cx = r.x; cx <= r.z; ++cx) atomic_inc(&cell_start[(uint)cy * d.x + (uint)cx + 1]);
}

// One work-item per triangle t: places t's entries in the cell-ordered list, each at
// its cell's next free place (an atomic on the cell's start, which so moves to the cell's
// end: afterwards cell c's entries are sorted_tri[cell_start[c] .. cell_start[c + 1]), in
// an order that depends on scheduling; the couples do not). Entries past `capacity` are
// not written (the host reads the total, grows and scatters again).
__kernel void cell_scatter(const uint n_triangles,
                           __global const float4* restrict boxes,
                           __global const real4* restrict grid,
                           __global const uint4* restrict dims,
                           volatile __global uint* cell_start,
                           const uint capacity,
                           __global uint* restrict sorted_tri) {
  const uint t = get_global_id(0);
  if (t >= n_triangles) return;
  const uint4 d = dims[0];
  const int4 r = entry_cells(load_box(boxes, t), grid[0], d);
  for (int cy = r.y; cy <= r.w; ++cy)
    for (int cx = r.x; cx <= r.z; ++cx) {
      const uint at = atomic_inc(&cell_start[(uint)cy * d.x + (uint)cx + 1]);
      if (at < capacity) sorted_tri[at] = t;
    }
}

// Insertion sort of one triangle's few keys, ascending, by the work-item that wrote them.
inline void sort_segment(__global ulong* segment, const uint n) {
  for (uint a = 1; a < n; ++a) {
    const ulong key = segment[a];
    uint b = a;
    while (b > 0 && segment[b - 1] > key) {
      segment[b] = segment[b - 1];
      --b;
    }
    segment[b] = key;
  }
}

// Whether triangles i and j have a node in common (not a contact couple: the mesh holds them).
inline bool shares_node(const uint i, const uint j, __global const uint* tri_nodes) {
  const uint a0 = tri_nodes[3 * i], a1 = tri_nodes[3 * i + 1], a2 = tri_nodes[3 * i + 2];
  const uint b0 = tri_nodes[3 * j], b1 = tri_nodes[3 * j + 1], b2 = tri_nodes[3 * j + 2];
  return a0 == b0 || a0 == b1 || a0 == b2 || a1 == b0 || a1 == b1 || a1 == b2 || a2 == b0 || a2 == b1 || a2 == b2;
}

// Whether one edge line of triangles a and b has all three vertices of the other more
// than `reach` outside it. The gap across an edge line is a lower bound on the distance
// between the two triangles, so then no point of a comes within `reach` of b. A detection
// lists a couple only when this is false for reach = the skin (both boxes' margins): a
// point of a triangle moves at most as far as its farthest node, and the list is
// replaced before any node has moved half the skin since the positions it was found on,
// so two triangles further apart than the skin cannot touch while the list stands; their
// boxes may still overlap (a triangle's box is up to twice its area's reach). Outside
// distance × |edge| is the cross product, signed by the triangle's orientation; it is
// compared squared (no square root), past a rounding allowance of 16 ε × the largest
// coordinate. A degenerate edge owner (zero area) separates nothing.
inline bool apart_beyond(const real2 a[3], const real2 b[3], const real reach) {
  real extent = (real)0;
  for (int m = 0; m < 3; ++m)
    extent = fmax(extent, fmax(fmax(fabs(a[m].x), fabs(a[m].y)), fmax(fabs(b[m].x), fabs(b[m].y))));
  const real allowed = reach + (real)16 * REAL_EPS * extent;
  for (int dir = 0; dir < 2; ++dir) {
    const real2 p0 = dir ? b[0] : a[0], p1 = dir ? b[1] : a[1], p2 = dir ? b[2] : a[2];
    const real2 q0 = dir ? a[0] : b[0], q1 = dir ? a[1] : b[1], q2 = dir ? a[2] : b[2];
    const real twice_area = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
    if (twice_area == (real)0) continue;
    const real outward = twice_area > (real)0 ? (real)-1 : (real)1;
    for (int m = 0; m < 3; ++m) {
      const real2 from = m == 0 ? p0 : m == 1 ? p1 : p2;
      const real2 to = m == 0 ? p1 : m == 1 ? p2 : p0;
      const real2 edge = to - from;
      const real g0 = outward * (edge.x * (q0.y - from.y) - edge.y * (q0.x - from.x));
      const real g1 = outward * (edge.x * (q1.y - from.y) - edge.y * (q1.x - from.x));
      const real g2 = outward * (edge.x * (q2.y - from.y) - edge.y * (q2.x - from.x));
      const real gap = fmin(fmin(g0, g1), g2);  // the nearest vertex's outside distance × |edge|
      if (gap > (real)0 && gap * gap > allowed * allowed * dot(edge, edge)) return true;
    }
  }
  return false;
}

inline void triangle_corners(const uint t, __global const uint* tri_nodes, __global const real2* position,
                             real2 x[3]) {
  x[0] = position[tri_nodes[3 * t]];
  x[1] = position[tri_nodes[3 * t + 1]];
  x[2] = position[tri_nodes[3 * t + 2]];
}

// The couples of triangle i, in one of two modes:
// - a detection (covered = 0xffffffff): the couples (i, j) with j > i that are
//   candidates (i and j both active, or with BONDED_PAIRS, activation "fractured", j one
//   of the up to three triangles a CE4 joins to i: bond_partners[3i .. 3i+2], NO_PARTNER
//   where none. Bonded couples take part from the start, active or not: their faces touch
//   along the CE4 and may overlap under compression; a couple switched on only when its
//   CE4 breaks would start with that overlap's contact energy, which no force supplied,
//   issue 11);
// - an extension by joins: when i joined after the list was made or last extended (mask
//   value, the join's stamp, above `covered`), its couples with every other candidate j,
//   except its bonded partners (in the list from the start) and, when j joined after
//   `covered` too, those with j < i (j lists them); keys (lower << 32 | higher).
// In both, j's box overlaps i's, j shares no node with i, and the two are not apart by
// more than the skin (apart_beyond, on `position`: the positions the boxes were taken
// from, which an extension is given again). i looks through the cells
// around its entries (3x3 around a small triangle's, the covered ones and a ring around
// them for a large one): a small j is there once, at its centre's cell; a large j may be
// in several of them, and counts in the first (row-major) cell of the two ranges' overlap.
// `part` of `parts` (GPUs: several work-items per triangle, for the latency of the cell
// walks; CPUs: one): the cells of i's range in row-major order number 0, 1, ...; this part
// walks cells part, part + parts, ... (a small triangle's 3x3 cells: one each with 9 parts).
// With `keys` each key goes to keys[atomic_inc(cursor)] (the order of the parts' writes
// depends on scheduling; sort_segments puts each triangle's segment in order after);
// returns the number of couples found by this part.
inline uint triangle_couples(const uint i,
                             const uint part,
                             const uint parts,
                             const uint covered,
                             __global const uint* tri_nodes,
                             __global const float4* boxes,
                             __global const uint* active,
                             __global const real4* grid,
                             __global const uint4* dims,
                             __global const uint* cell_start,
                             __global const uint* sorted_tri,
                             const uint n_entries,
                             __global const real2* position,
                             const real reach,
#ifdef BONDED_PAIRS
                             __global const uint* bond_partners,
#endif
#ifdef OWNED_FIRST
                             __global const uchar* owned_first,
#endif
                             __global ulong* keys,
                             __global uint* cursor) {
  const bool extension = covered != 0xffffffffu;
#ifdef LIST_INACTIVE
  // Couples listed ahead of their triangles' joins (activation "fractured" with a skin):
  // a full detection lists every couple as if all took part; the contact stage lets only
  // couples of two active triangles act, from the very step the second one joins.
  const uint stamp_i = extension ? active[i] : 1u;
#else
  const uint stamp_i = active[i];
#endif
#ifdef BONDED_PAIRS
  const uint p0 = bond_partners[3 * i], p1 = bond_partners[3 * i + 1], p2 = bond_partners[3 * i + 2];
#else
  const uint p0 = NO_PARTNER, p1 = NO_PARTNER, p2 = NO_PARTNER;
#endif
  if (extension) {
    if (stamp_i <= covered) return 0;
  } else {
#ifdef OWNED_FIRST
    // A split run: this rank lists only the couples whose lower triangle it owns.
    if (owned_first[i] == 0) return 0;
#endif
    if (stamp_i == 0) {
      // Not a candidate itself: only its bonded partners j > i, looked at directly (no
      // cells; in an intact fracture model that is nearly every triangle), by part 0.
      if (part != 0) return 0;
      const real4 box = load_box(boxes, i);
      const uint partner[3] = {p0, p1, p2};
      real2 xi[3], xj[3];
      triangle_corners(i, tri_nodes, position, xi);
      uint found = 0;
      for (int k = 0; k < 3; ++k) {
        const uint j = partner[k];
        if (j == NO_PARTNER || j <= i || !boxes_overlap(box, load_box(boxes, j)) || shares_node(i, j, tri_nodes)) continue;
        triangle_corners(j, tri_nodes, position, xj);
        if (apart_beyond(xi, xj, reach)) continue;
        if (keys) keys[atomic_inc(cursor)] = ((ulong)i << 32) | (ulong)j;
        ++found;
      }
      return found;
    }
  }
  const uint4 d = dims[0];
  const real4 g = grid[0];
  const real4 box = load_box(boxes, i);
  const int4 mine = entry_cells(box, g, d);
  real2 xi[3], xj[3];
  triangle_corners(i, tri_nodes, position, xi);
  const int x_lo = max(mine.x - 1, 0), x_hi = min(mine.z + 1, (int)d.x - 1);
  const int y_lo = max(mine.y - 1, 0), y_hi = min(mine.w + 1, (int)d.y - 1);
  uint found = 0;
  const uint width = (uint)(x_hi - x_lo + 1), cells = width * (uint)(y_hi - y_lo + 1);
  for (uint cell = part; cell < cells; cell += parts) {
    {
      const int cy = y_lo + (int)(cell / width), cx = x_lo + (int)(cell % width);
      const uint h = (uint)cy * d.x + (uint)cx;
      // (min: after an overflow of the entries the host sorts again; read nothing past them)
      const uint end = min(cell_start[h + 1], n_entries);
      for (uint k = cell_start[h]; k < end; ++k) {
        const uint j = sorted_tri[k];
#ifdef LIST_INACTIVE
        const uint stamp_j = extension ? active[j] : 1u;
#else
        const uint stamp_j = active[j];
#endif
        const bool bonded = j == p0 || j == p1 || j == p2;
        if (extension) {
          if (j == i || stamp_j == 0 || (stamp_j > covered && j < i) || bonded) continue;
        } else {
          if (j <= i || !((stamp_i != 0 && stamp_j != 0) || bonded)) continue;
        }
        const real4 other = load_box(boxes, j);
        if (!boxes_overlap(box, other)) continue;
        const int4 theirs = entry_cells(other, g, d);
        if (theirs.x != theirs.z || theirs.y != theirs.w) {  // large j: only in the overlap's first cell
          if (cy != max(y_lo, theirs.y) || cx != max(x_lo, theirs.x)) continue;
        }
        if (shares_node(i, j, tri_nodes)) continue;
        triangle_corners(j, tri_nodes, position, xj);
        if (apart_beyond(xi, xj, reach)) continue;
        if (keys) keys[atomic_inc(cursor)] = i < j ? ((ulong)i << 32) | (ulong)j : ((ulong)j << 32) | (ulong)i;
        ++found;
      }
    }
  }
  return found;
}

#ifdef BONDED_PAIRS
#define BOND_ARG , bond_partners
#define BOND_PARAM , __global const uint* restrict bond_partners
#else
#define BOND_ARG
#define BOND_PARAM
#endif
#ifdef OWNED_FIRST
#define OWNED_ARG , owned_first
#define OWNED_PARAM , __global const uchar* restrict owned_first
#else
#define OWNED_ARG
#define OWNED_PARAM
#endif

// One work-item per part p of triangle i (global id p·n + i, so that neighbouring
// work-items read neighbouring triangles): adds the couples that part finds
// (triangle_couples; covered = 0xffffffff for a detection, the list's covered join stamp
// for an extension) to couple_offset[i], zeroed before. Integer sums: the same total in
// any order. The prefix sum over the triangles then makes them the segments' starts, and
// entry n_triangles (zero) the total.
__kernel void couple_count(const uint n_triangles,
                           const uint parts,
                           const uint covered,
                           __global const uint* restrict tri_nodes,
                           __global const float4* restrict boxes,
                           __global const uint* restrict active,
                           __global const real4* restrict grid,
                           __global const uint4* restrict dims,
                           __global const uint* restrict cell_start,
                           __global const uint* restrict sorted_tri,
                           const uint n_entries,
                           __global const real2* restrict position,
                           const real reach,
                           __global uint* restrict couple_offset BOND_PARAM OWNED_PARAM) {
  const uint id = get_global_id(0);
  if (id >= n_triangles * parts) return;
  const uint i = id % n_triangles, part = id / n_triangles;
  const uint found = triangle_couples(i, part, parts, covered, tri_nodes, boxes, active, grid, dims, cell_start,
                                      sorted_tri, n_entries, position, reach BOND_ARG OWNED_ARG, (__global ulong*)0,
                                      (__global uint*)0);
  if (found) atomic_add(&couple_offset[i], found);
}

// One work-item per part p of triangle i (as couple_count): writes the couples it finds
// into i's segment keys[listed + start_i ..) at places taken by atomic_inc on
// couple_offset[i], which holds start_i (after the prefix sum) and ends at start_i +
// count_i = start_{i+1}: afterwards couple_offset[i] is i's segment's end and
// couple_offset[i - 1] its start (0 for i = 0). `listed`: 0 for a detection; for an
// extension the couples already listed (the new ones follow them, by joining triangle).
// The host has grown `keys` to the total before.
__kernel void couple_write(const uint n_triangles,
                           const uint parts,
                           const uint covered,
                           __global const uint* restrict tri_nodes,
                           __global const float4* restrict boxes,
                           __global const uint* restrict active,
                           __global const real4* restrict grid,
                           __global const uint4* restrict dims,
                           __global const uint* restrict cell_start,
                           __global const uint* restrict sorted_tri,
                           const uint n_entries,
                           __global const real2* restrict position,
                           const real reach,
                           __global uint* restrict couple_offset,
                           const uint listed,
                           __global ulong* restrict keys BOND_PARAM OWNED_PARAM) {
  const uint id = get_global_id(0);
  if (id >= n_triangles * parts) return;
  const uint i = id % n_triangles, part = id / n_triangles;
  triangle_couples(i, part, parts, covered, tri_nodes, boxes, active, grid, dims, cell_start, sorted_tri, n_entries,
                   position, reach BOND_ARG OWNED_ARG, keys + listed, &couple_offset[i]);
}

// One work-item per triangle i: sorts its segment of couple_write's keys ascending
// (insertion sort: a few entries), so that the list's order does not depend on the
// order the parts wrote in. couple_offset[i] is the segment's end (see couple_write).
__kernel void sort_segments(const uint n_triangles,
                            __global const uint* restrict couple_offset,
                            const uint listed,
                            __global ulong* restrict keys) {
  const uint i = get_global_id(0);
  if (i >= n_triangles) return;
  const uint first = i ? couple_offset[i - 1] : 0u, end = couple_offset[i];
  if (end - first > 1) sort_segment(keys + listed + first, end - first);
}
