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

#ifdef HALO_CONTACT
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
// Contact in a split run (HaloExchange::exchange_contact): the fixed-point contact force
// (contact_acc, two longs per node) that this rank's couples put on its ghost nodes goes
// to their owners. One work-item per ghost node k sent: copies local node index[k]'s.
__kernel void halo_contact_pack(const uint n,
                                __global const uint* restrict index,
                                __global const long* restrict contact_acc,
                                __global long2* restrict packed) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  const uint i = index[k];
  packed[k] = (long2)(contact_acc[2 * i], contact_acc[2 * i + 1]);
}

// One work-item per owned node k received from a peer: adds packed[k] to local node
// index[k]'s. A node held by several peers is in several peers' lists, so the additions
// are integer atomics (exact, and their order does not matter).
__kernel void halo_contact_add(const uint n,
                               __global const uint* restrict index,
                               __global const long2* restrict packed,
                               volatile __global long* contact_acc) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  const uint i = index[k];
  const long2 f = packed[k];
  if (f.x != 0) atom_add(&contact_acc[2 * i], f.x);
  if (f.y != 0) atom_add(&contact_acc[2 * i + 1], f.y);
}
#endif
