// Contact history carry-over at a new detection (engine/stages/contact_carry.hpp).
// Only couples whose live flag is nonzero hold a history (a couple that stopped
// overlapping had its history cleared by contact_forces.cl's forget_couple), so before
// the detection rewrites the list, the keys and histories of those couples are copied,
// in list order, to a compact carry list. The new list then finds its couples' histories
// there (carry_locate: each carried couple looks itself up in the new, ascending list), and the one history array of the contact
// stage is rewritten in place. Also carried, with their (zero) history: couples of which
// a triangle joined the candidates since the last list (mask value >= joined_since), so
// that contact_forces still sees them as old couples (found), not as couples met over
// an overlap because of the join (under "fractured" the two triangles of a CE4 are a
// couple before either joins).
//
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two), NO_SLOT (an
// empty entry of the contact stage's slot array: the couple holds no history row).
// Layout: CONTACT_HISTORY reals per couple (engine/layouts.hpp); the contact stage keeps
// them in a pool, couple c's at row slot[c] (contact_forces.cl).

// Whether couple c of the list is carried: live, or a triangle joined since the last list.
inline uint carried(const uint c, const uint n_couples, __global const uchar* live, __global const ulong* keys,
                    __global const uint* active, const uint joined_since) {
  if (c >= n_couples) return 0u;
  if (live[c] != 0) return 1u;
  const ulong key = keys[c];
  return (active[(uint)(key >> 32)] >= joined_since || active[(uint)(key & 0xffffffffu)] >= joined_since) ? 1u : 0u;
}

// One work-item per couple c of the current list: the number of carried couples in its
// work-group goes to group_counts[group].
__kernel void carry_count(const uint n_couples,
                          __global const uchar* restrict live,
                          __global const ulong* restrict keys,
                          __global const uint* restrict active,
                          const uint joined_since,
                          __global uint* restrict group_counts) {
  __local uint scratch[GROUP_SIZE];
  const uint c = get_global_id(0);
  const uint flag = carried(c, n_couples, live, keys, active, joined_since);
  uint total;
  group_exclusive_scan(scratch, flag, &total);
  if (get_local_id(0) == 0) group_counts[get_group_id(0)] = total;
}

// Launched as ONE work-group. Replaces group_counts[0 .. n_groups) by their exclusive
// prefix sums (work-item l takes a contiguous run of groups) and writes the number of
// carried couples to carry_count[0].
__kernel void carry_offsets(const uint n_groups,
                            __global uint* restrict group_counts,
                            __global uint* restrict carry_count) {
  __local uint scratch[GROUP_SIZE];
  const uint total = group_scan_global(scratch, group_counts, n_groups);
  if (get_local_id(0) == 0) carry_count[0] = total;
}

// One work-item per couple c of the current list: a carried couple copies its key and
// history (from its pool row) to the carry list at its rank among the carried couples (group offset + rank
// in the group), so the carry list keeps the list's (ascending key) order.
__kernel void carry_scatter(const uint n_couples,
                            __global const uchar* restrict live,
                            __global const ulong* restrict keys,
                            __global const uint* restrict active,
                            const uint joined_since,
                            __global const real* restrict history,
                            __global const uint* restrict slot,
                            __global const uint* restrict group_offsets,
                            __global ulong* restrict carry_keys,
                            __global real* restrict carry_history) {
  __local uint scratch[GROUP_SIZE];
  const uint c = get_global_id(0);
  const uint flag = carried(c, n_couples, live, keys, active, joined_since);
  uint total;
  const uint rank = group_exclusive_scan(scratch, flag, &total);
  if (!flag) return;
  const uint at = group_offsets[get_group_id(0)] + rank;
  const uint row = slot[c];  // the couple's row in the history pool (NO_SLOT: none, the zero history)
  carry_keys[at] = keys[c];
  for (int h = 0; h < CONTACT_HISTORY; ++h)
    carry_history[CONTACT_HISTORY * at + h] = row != NO_SLOT ? history[CONTACT_HISTORY * row + h] : (real)0;
}

// One work-item per carried couple r: finds it in the new list (ascending keys: a binary
// search) and, when there, writes its carry-list row to carry_of[c] of its place c, where
// the new list's first classification reads it (carry_of holds NO_SLOT for every other
// couple). The carry list itself keeps the old list's order, which need not be ascending
// once the old list was extended by joins (ContactDetection::extend_joined).
__kernel void carry_locate(const uint n_carried,
                           __global const ulong* restrict carry_keys,
                           const uint n_couples,
                           __global const ulong* restrict keys,
                           __global uint* restrict carry_of) {
  const uint r = get_global_id(0);
  if (r >= n_carried) return;
  const int c = find_key(keys, n_couples, carry_keys[r]);
  if (c >= 0) carry_of[c] = r;
}
