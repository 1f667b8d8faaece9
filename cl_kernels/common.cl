// Shared by every stage: precision typedefs, small 2x2 matrix helpers, the layout of
// the material table and of the condition flags. Prepended to each stage's source.
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

// Material table: MATERIAL_STRIDE reals per material (engine/materials.hpp fills it).
#define MATERIAL_STRIDE 12
#define MAT_MODEL 0        /* 0 Neo-Hookean (Eq. 1), 1 hyperelastic (Eqs. 2-3) */
#define MAT_LAMBDA 1       /* Lamé λ of the 2D model [Pa] (plane stress: 2λμ/(λ+2μ)) */
#define MAT_MU 2           /* shear modulus μ [Pa] */
#define MAT_C11 3          /* Voigt stiffness, global frame, on (xx, yy, 2xy) [Pa] */
#define MAT_C12 4
#define MAT_C16 5
#define MAT_C22 6
#define MAT_C26 7
#define MAT_C66 8
#define MAT_VISCOSITY 9    /* η of the viscous stress η D [Pa s] */
#define MAT_DENSITY 10     /* ρ [kg/m³] */
#define MAT_RESERVED 11     /* unused */

// Condition flags: the first (lowest-index) offender of each kind and the step.
// The host initialises every word to INT_MAX and reads them at checks.
#define COND_BAD_NODE 0       /* node whose position or velocity became NaN/inf */
#define COND_BAD_NODE_STEP 1
#define COND_INVERTED_TRI 2   /* triangle whose Jacobian became <= 0 */
#define COND_INVERTED_STEP 3
#define CONDITION_WORDS 4

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
