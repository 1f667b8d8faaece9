// Host mirror of the device's `real` type. A build with -DFDEM_PRECISION=float makes
// both float; the default is double. real2/real4 match OpenCL's real2/real4 in size
// (8/16 bytes for float, 16/32 for double), so arrays of them can be copied as bytes.
#pragma once

namespace fdem {

#ifdef FDEM_FLOAT
using real = float;
inline constexpr bool kDoublePrecision = false;
#else
using real = double;
inline constexpr bool kDoublePrecision = true;
#endif

struct real2 {
  real x = 0, y = 0;
};
struct real4 {
  real x = 0, y = 0, z = 0, w = 0;
};
static_assert(sizeof(real2) == 2 * sizeof(real), "real2 must be packed like OpenCL's");
static_assert(sizeof(real4) == 4 * sizeof(real), "real4 must be packed like OpenCL's");

}  // namespace fdem
