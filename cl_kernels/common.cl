// Shared by every stage: precision typedefs, small 2x2 matrix helpers, the work-group
// sum. Prepended to each stage's source.
#ifdef FDEM_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double real;
typedef double2 real2;
typedef double3 real3;
typedef double4 real4;
#else
typedef float real;
typedef float2 real2;
typedef float3 real3;
typedef float4 real4;
#endif

// A 2x2 matrix as real4 (x, y, z, w) = (m00, m01, m10, m11), row-major.
inline real det2(real4 m) { return m.x * m.w - m.y * m.z; }
inline real4 mul2(real4 a, real4 b) {
  return (real4)(a.x * b.x + a.y * b.z, a.x * b.y + a.y * b.w,
                 a.z * b.x + a.w * b.z, a.z * b.y + a.w * b.w);
}
inline real4 transpose2(real4 m) { return (real4)(m.x, m.z, m.y, m.w); }
inline real4 inverse2(real4 m) {
  const real inv = (real)1 / det2(m);
  return (real4)(m.w * inv, -m.y * inv, -m.z * inv, m.x * inv);
}

// The layouts of the material table (MAT_*, MATERIAL_STRIDE), the condition words
// (COND_*, CONDITION_WORDS) and the other arrays shared with the host are #defines that
// ClContext::build prepends from engine/layouts.hpp, where each is written once.

// Work-group sum of one real4 per work-item by a fixed pairwise tree, so the sum and its
// rounding are the same on every run; the result is valid in work-item 0. Every
// work-item of the group must call it (it holds barriers); the local size must be a power
// of two (ClContext makes it one). Energy accounts use it: each group's sum goes to its
// own slot, and the host adds the slots in order.
inline real4 group_sum4(__local real4* scratch, real4 value) {
  const uint lid = get_local_id(0);
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = get_local_size(0) / 2; s > 0; s >>= 1) {
    if (lid < s) scratch[lid] += scratch[lid + s];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  return scratch[0];
}

// Work-group maxima by the same fixed tree: of one real4 per work-item (componentwise
// fmax; for a minimum pass the negated value) and of one uint2 (integer max: float bits
// of non-negative values order as the values, and NaN bits above +inf, so a NaN is never
// lost). Valid in work-item 0; every work-item must call them (barriers).
inline real4 group_max4(__local real4* scratch, real4 value) {
  const uint lid = get_local_id(0);
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = get_local_size(0) / 2; s > 0; s >>= 1) {
    if (lid < s) scratch[lid] = fmax(scratch[lid], scratch[lid + s]);
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  return scratch[0];
}

inline uint2 group_max_uint2(__local uint2* scratch, uint2 value) {
  const uint lid = get_local_id(0);
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
#ifdef FDEM_CPU_DEVICE
  // A CPU device runs the group's items one after the other, each tree level a pass over
  // all of them (8 passes for 256 items: a third of the integration's time on PoCL), so
  // work-item 0 takes the maximum alone; an integer maximum is the same in any order.
  if (lid == 0) {
    uint2 largest = scratch[0];
    for (uint k = 1; k < get_local_size(0); ++k) largest = max(largest, scratch[k]);
    scratch[0] = largest;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
#else
  for (uint s = get_local_size(0) / 2; s > 0; s >>= 1) {
    if (lid < s) scratch[lid] = max(scratch[lid], scratch[lid + s]);
    barrier(CLK_LOCAL_MEM_FENCE);
  }
#endif
  return scratch[0];
}

// Exclusive prefix sum of `value` over the work-group (Hillis-Steele in local memory;
// integers, so the order of the additions does not matter); *total receives the group's
// sum. Every work-item of the group must call it (barriers). Used by the carry-over and
// by contact detection's counting sort.
inline uint group_exclusive_scan(__local uint* scratch, const uint value, uint* total) {
  const uint lid = get_local_id(0);
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint offset = 1; offset < get_local_size(0); offset <<= 1) {
    const uint add = lid >= offset ? scratch[lid - offset] : 0u;
    barrier(CLK_LOCAL_MEM_FENCE);
    scratch[lid] += add;
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  const uint inclusive = scratch[lid];
  *total = scratch[get_local_size(0) - 1];
  barrier(CLK_LOCAL_MEM_FENCE);  // scratch is free again
  return inclusive - value;
}

// Exclusive prefix sum, in place, of values[0 .. n) by ONE work-group (work-item l takes
// a contiguous run of them, the group scans the runs' sums); returns the total. Every
// work-item of the group must call it (barriers). For the prefix sums of per-block or
// per-group totals (contact detection's scans, the carry-over's offsets).
inline uint group_scan_global(__local uint* scratch, __global uint* values, const uint n) {
  const uint size = get_local_size(0), lid = get_local_id(0);
  const uint per = (n + size - 1) / size;
  const uint first = min(lid * per, n), last = min(first + per, n);
  uint sum = 0;
  for (uint k = first; k < last; ++k) sum += values[k];
  uint total;
  uint running = group_exclusive_scan(scratch, sum, &total);
  for (uint k = first; k < last; ++k) {
    const uint count = values[k];
    values[k] = running;
    running += count;
  }
  return total;
}

// Index of `key` in the ascending list keys[0 .. n), or -1 (binary search).
inline int find_key(__global const ulong* keys, uint n, ulong key) {
  uint lo = 0, hi = n;
  while (lo < hi) {
    const uint mid = (lo + hi) / 2;
    const ulong k = keys[mid];
    if (k < key) lo = mid + 1;
    else if (k > key) hi = mid;
    else return (int)mid;
  }
  return -1;
}
