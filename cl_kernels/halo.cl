// The halo exchange of a split run (engine/halo.*): the positions and velocities of the
// nodes a rank owns and others hold as ghosts travel once a step, after the
// integration. Packing them into one compact array makes the host read one buffer.

// One work-item per sent node k: copies (position, velocity) of local node index[k]
// into packed[k].
__kernel void halo_pack(const uint n,
                        __global const uint* restrict index,
                        __global const real2* restrict position,
                        __global const real2* restrict velocity,
                        __global real4* restrict packed) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  const uint i = index[k];
  packed[k] = (real4)(position[i], velocity[i]);
}

// One work-item per received ghost node k: writes packed[k] into the position and
// velocity of local node index[k].
__kernel void halo_unpack(const uint n,
                          __global const uint* restrict index,
                          __global const real4* restrict packed,
                          __global real2* restrict position,
                          __global real2* restrict velocity) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  const uint i = index[k];
  const real4 p = packed[k];
  position[i] = p.xy;
  velocity[i] = p.zw;
}
