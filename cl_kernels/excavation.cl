// [[excavation]]: the factor k(time) of excavation i (excavation_time: (start, duration)
// [s] per excavation; duration 0: at once): 1 before start, 0 from start + duration on,
// linear between. A library (ClContext::build) of the stages that ramp or drop what an
// excavation removes, built with it only in models with [[excavation]]: triangle_forces.cl,
// cohesive_forces.cl and contact_forces.cl, so a triangle, its CE4s and its contact
// couples take the same bits.
inline real excavation_factor(__global const real* restrict excavation_time, const int i, const real time) {
  const real start = excavation_time[2 * i], duration = excavation_time[2 * i + 1];
  if (time < start) return (real)1;
  if (!(duration > (real)0) || time >= start + duration) return (real)0;
  return (real)1 - (time - start) / duration;
}
