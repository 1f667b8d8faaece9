// Munjiza potential contact between triangle couples, with Coulomb friction and
// An-Tannant damping. One work-item per couple (i < j, from contact detection):
//   normal force  f_c = P_n ∫_{c∩t} (∇φ_c − ∇φ_t) dA, evaluated exactly as boundary
//     integrals: for each edge of one triangle, the potential φ of the other (linear on
//     each of its three centroid sub-triangles, zero outside) is integrated along the
//     part of the edge inside it; the result acts normal to the edge, on the edge's
//     nodes by the lever rule and, opposite, on the other triangle's nodes by their
//     barycentric weights at the same points (zero net force and moment); plus an area
//     term per triangle, so that the nodal forces are the exact gradient of the
//     potential E = P_n t ∫_{c∩t}(φ_c + φ_t) dA (see couple_potential);
//   damping       the couple's total normal force is scaled by σ/σ_try of Eq. 15;
//   friction      per edge pass, an elastic slip spring P_tan × L × t × slip at the normal
//     force's acting point, capped at μ × normal force (Eq. 16).
// Forces go to the nodes through 64-bit fixed-point atomic adds (integer addition is
// associative, so the sums are bitwise reproducible whatever the order).
//
// Energy (issue 11). The integrator (central difference) changes the kinetic energy by
// exactly f_n·(x_{n+1} − x_{n−1})/2 per step, which summed by parts is the trapezoid rule
// ½ (f_{n−1} + f_n)·(x_n − x_{n−1}) per step. Every dissipation below is that work less
// the change of the energy the couple stores, so kinetic + stored + dissipated is
// conserved to the integrator's own O(Δt²) and nothing is created or lost unbooked.
// What this changes against the paper / Y-Geo formulation:
//   - the slip spring's stiffness is P_tan L t with L the whole edge (not the length of
//     the edge inside the other triangle, which changes every step: a stiffness that
//     changes without motion changes the spring's force and energy without work; in an
//     undamped sliding block that lost 13% of the energy and let it slide 30% too far);
//     P_tan is per unit length of the edge pass;
//   - friction dissipation is the spring's trapezoid work less the change of its energy,
//     ½ (k_prev s_prev Δs_prev + k s Δs) + ½ k_prev s_prev² − ½ k s², instead of μ F_n ×
//     (plastic slip): the latter misses ½ Δσ²/k whenever the cap moves, and the spring's
//     energy when a couple lets go (3% of the friction work with a bouncing block); a pass
//     or couple that lets go books its spring's energy and last half step. Δs_prev is the
//     step's move measured as the last step's force acts (its acting point, barycentric
//     weights, tangent and stiffness, rebuilt from x − v Δt, see old_spring), Δs as this
//     step's acts: booking ½ (s_prev + s) Δs with this step's measure alone (the acting
//     point s* = I1/I moves as the pressure along the pass changes, and the two bodies
//     strain differently along it) was 2e-4 of the friction work off in a rocking block;
//   - the area term of the normal force (the exact gradient; the edge passes alone are
//     the gradient for rigid motions only);
//   - the damping is booked as it happens (held work above ratio × E), not when the
//     couple lets go, with the trapezoid rule (the one-sided rule booked 3.5% too much).
// History per couple (CONTACT_HISTORY reals, HIST_* below), carried over from the
// previous couple list by binary search on the key. Histories live in a pool (`history`),
// one row per couple that has written one since the last detection: slot[c] is couple
// c's row, NO_SLOT (a host define) until its first write takes one (take_slot); a new
// list starts with every slot empty (classify) and the pool empty (the host), its couples'
// old histories being read from the carry list (contact_carry.cl). A couple without a
// row holds the zero history.
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable

// The history slots (HIST_*, CONTACT_HISTORY; 0-5 the slip of each edge pass) and the
// material-pair row (PAIR_*, CONTACT_PROPS) are defined in engine/layouts.hpp.
// The stage's cumulative dissipation, 64-bit fixed point (energy_scale units): friction
// and contact damping. Each couple books whole units only and carries the rest to its next
// step (friction: HIST_REST; damping: back into HIST_HELD), so nothing is lost to the
// rounding: each couple's increments of a step are often below the unit (2⁻³² J), and
// rounding every one of them to the nearest unit lost 1.1% of the friction work of a block
// creeping on an incline (5 couples, 3e-10 J a step each). (The stored energy of an energy row goes to couple_stored, summed
// in couple order: a row's value needs more resolution than 2⁻³² J per couple.) The
// words' indices (ENERGY_FRICTION, ENERGY_DAMPING) are in engine/layouts.hpp.

// The couple geometry (integrate_potential, couple_potential, couple_nodes,
// barycentric_values, separated) is in cl_kernels/couple_geometry.cl, built ahead of this file.

// A force term on vertex a of triangle k of the couple. With CONTACT_SUM_PER_COUPLE
// (the host sets it for CPU devices, where each 64-bit atomic is a locked instruction)
// the terms are summed per vertex in a fixed order and added once per node at the end;
// on GPUs each term goes out at once (holding the sums costs registers and was slower).
#ifdef CONTACT_SUM_PER_COUPLE
#define COUPLE_FORCE(k, a, f) fnode[k][a] += (f)
#else
#define COUPLE_FORCE(k, a, f) add_force(contact_acc, nodes[k][a], (f), force_scale)
#endif

inline void add_force(__global long* acc, uint node, real2 f, real scale) {
  atom_add(&acc[2 * node], convert_long_rte(f.x * scale));
  atom_add(&acc[2 * node + 1], convert_long_rte(f.y * scale));
}

// The row in the carry list of couple c of a new list (ContactCarry::locate wrote it,
// NO_SLOT when the couple was not carried), or -1.
inline int carried_row(const uint c, __global const uint* carry_of) {
  const uint row = carry_of[c];
  return row == NO_SLOT ? -1 : (int)row;
}

// A couple that does not touch: the couple let go. What its friction springs held (their
// energy and the half step of work of their last forces, HIST_PENDING) counts as
// dissipated, and its history is forgotten: its pool row `row` (-1: none, as in a new
// list, whose couples hold no row yet) is zeroed where not zero yet, so untouched
// couples write nothing. `found`: the history's row in previous_history (-1: none).
// `removed` (EXCAVATION only): the couple stops because one of its triangles is being
// excavated, not because it let go: an undamped couple (HIST_RATIO 0) still holds its
// potential of the last step (HIST_ENERGY), which is booked with the held work.
inline void forget_couple(const int row, const int found, __global const real* previous_history,
                          __global real* history, const real energy_scale, __global long* energy,
                          const bool removed) {
  real pending = (real)0, held = (real)0, ratio = (real)0, potential = (real)0;
  bool stored = false;
  for (int h = 0; h < CONTACT_HISTORY; ++h) {
    const real value = found >= 0 ? previous_history[CONTACT_HISTORY * found + h] : (real)0;
    if (h == HIST_PENDING || h == HIST_REST) pending += value;
    if (h == HIST_HELD) held = value;
    if (h == HIST_RATIO) ratio = value;
    if (h == HIST_ENERGY) potential = value;
    stored = stored || value != (real)0;
  }
  if (removed && ratio == (real)0) held += potential;
  if (pending != (real)0) atom_add(&energy[ENERGY_FRICTION], convert_long_rte(pending * energy_scale));
  if (held != (real)0) atom_add(&energy[ENERGY_DAMPING], convert_long_rte(held * energy_scale));
  if (stored && row >= 0)
    for (int h = 0; h < CONTACT_HISTORY; ++h) history[CONTACT_HISTORY * row + h] = (real)0;
}

// Couple c's pool row (-1: none yet).
inline int pool_row(const uint c, __global const uint* slot) {
  const uint s = slot[c];
  return s == NO_SLOT ? -1 : (int)s;
}

// Couple c's pool row, taken from the pool (pool_state[0]: rows taken) at its first
// write. A full pool (more couples touched since the last detection than the host made
// room for; it grows the pool from the monitor ring's RING_POOL word) gives -1 and keeps
// the first such step in pool_state[1]: the host stops the run there.
inline int take_slot(const uint c, __global uint* slot, __global uint* pool_state, const uint pool_capacity,
                     const int step) {
  const uint s = slot[c];
  if (s != NO_SLOT) return (int)s;
  const uint fresh = atomic_inc(&pool_state[0]);
  if (fresh >= pool_capacity) {
    atomic_min(&pool_state[1], (uint)step);
    return -1;
  }
  slot[c] = fresh;
  return (int)fresh;
}

#ifdef CE4_BONDS
// The state word of the CE4 that joins triangles i and j (cohesive_forces.cl: 0 intact,
// 1 broken and closed, 2 + n released at step n), or -1 when no CE4 joins them.
// bond_ce4[3t .. 3t+2]: the CE4s on triangle t's edges (NO_BOND where none): a CE4
// listed by both triangles is the one between them.
inline int bond_state(const uint i, const uint j, __global const uint* bond_ce4, __global const int2* ce4_status) {
  for (int a = 0; a < 3; ++a) {
    const uint e = bond_ce4[3 * i + a];
    if (e == NO_BOND) continue;
    if (e == bond_ce4[3 * j] || e == bond_ce4[3 * j + 1] || e == bond_ce4[3 * j + 2]) return ce4_status[e].x;
  }
  return -1;
}
#ifdef CORNER_FANS
// Triangles i and j that meet at one mesh node only (a corner; each node of a split mesh
// is a copy, node_origin[n] the mesh node it copies): that node's state word
// (cohesive_forces.cl: 0 while every CE4 at it is intact, 2 + n from the step n one of
// them broke, -1 when its fan is not bonded). -1 otherwise.
inline int corner_state(const uint i, const uint j, __global const uint* tri_nodes, __global const uint* node_origin,
                        __global const int* mesh_node_state) {
  const uint a0 = node_origin[tri_nodes[3 * i]], a1 = node_origin[tri_nodes[3 * i + 1]],
             a2 = node_origin[tri_nodes[3 * i + 2]];
  int shared = 0;
  uint v = 0;
  for (int k = 0; k < 3; ++k) {
    const uint b = node_origin[tri_nodes[3 * j + k]];
    if (b == a0 || b == a1 || b == a2) {
      ++shared;
      v = b;
    }
  }
  return shared == 1 ? mesh_node_state[v] : -1;
}
#define BOND_ARGS                                                                                      \
  , __global const uint *restrict bond_ce4, __global const int2 *restrict ce4_status,                 \
      __global const uint *restrict node_origin, __global const int *restrict mesh_node_state
#define BOND_PASS , bond_ce4, ce4_status, node_origin, mesh_node_state
#else
#define BOND_ARGS , __global const uint *restrict bond_ce4, __global const int2 *restrict ce4_status
#define BOND_PASS , bond_ce4, ce4_status
#endif

// The top bit of a bond word marks a corner (ContactForces keeps CE4 and node indices below it).
#define CORNER_BOND 0x80000000u

// What would carry couple (i, j) instead of contact, from the mesh alone (the triangles'
// CE4s and nodes never change, so contact_classify works it out once per couple of a list
// and keeps it in bond_word): the index of the CE4 that joins them; with bonded fans,
// CORNER_BOND | v when they meet at mesh node v only; NO_BOND otherwise. The same test
// as bond_state, then corner_state where no CE4 joins them.
inline uint couple_bond(const uint i, const uint j, __global const uint* bond_ce4, __global const uint* tri_nodes
#ifdef CORNER_FANS
                        , __global const uint* node_origin
#endif
                        ) {
  for (int a = 0; a < 3; ++a) {
    const uint e = bond_ce4[3 * i + a];
    if (e == NO_BOND) continue;
    if (e == bond_ce4[3 * j] || e == bond_ce4[3 * j + 1] || e == bond_ce4[3 * j + 2]) return e;
  }
#ifdef CORNER_FANS
  const uint a0 = node_origin[tri_nodes[3 * i]], a1 = node_origin[tri_nodes[3 * i + 1]],
             a2 = node_origin[tri_nodes[3 * i + 2]];
  int shared = 0;
  uint v = 0;
  for (int k = 0; k < 3; ++k) {
    const uint b = node_origin[tri_nodes[3 * j + k]];
    if (b == a0 || b == a1 || b == a2) {
      ++shared;
      v = b;
    }
  }
  if (shared == 1) return CORNER_BOND | v;
#endif
  return NO_BOND;
}

// The state of what bond_word `word` names, as bond_state and corner_state give it: the
// CE4's state word, the corner's mesh-node state, or -1 for NO_BOND.
inline int bond_word_state(const uint word, __global const int2* ce4_status
#ifdef CORNER_FANS
                           , __global const int* mesh_node_state
#endif
                           ) {
  if (word == NO_BOND) return -1;
#ifdef CORNER_FANS
  if (word & CORNER_BOND) return mesh_node_state[word & ~CORNER_BOND];
#endif
  return ce4_status[word].x;
}

// contact_classify's own: the per-couple words and whether this list's are written yet.
#define CLASSIFY_BOND_ARGS , __global uint *restrict bond_word, const uint bond_words_known
#define CLASSIFY_BOND_PASS , bond_word, bond_words_known
#ifdef SLEEPERS
// Whether no bond carries the couple (for the awake list of a full classification).
#define AWAKE_ARGS , bool *unbonded
#define AWAKE_PASS , &unbonded
#else
#define AWAKE_ARGS
#define AWAKE_PASS
#endif
#else
#define BOND_ARGS
#define BOND_PASS
#define CLASSIFY_BOND_ARGS
#define CLASSIFY_BOND_PASS
#define AWAKE_ARGS
#define AWAKE_PASS
#endif

#ifdef EXCAVATION
// [[excavation]]: triangle t is being excavated at this step when its excavation's factor
// (excavation_factor, excavation.cl, at step × dt as the triangle stage takes it) is below 1.
// A couple with such a triangle takes no part in contact from that step on (the factor
// never rises again): contact_classify forgets it at once, booking what it held as a
// couple that lets go books it (its friction springs' energy and last half step as
// friction; its damped held work, or an undamped couple's potential of the last step, as
// contact damping), so the account stays closed.
#define EXCAV_ARGS                                                                                  \
  , __global const int *restrict excavation_of, __global const real *restrict excavation_time,     \
      const real excavation_dt, const int excavation_step
#define EXCAV_PASS , excavation_of, excavation_time, excavation_dt, excavation_step
inline bool excavated_triangle(const uint t, __global const int* excavation_of, __global const real* excavation_time,
                               const real dt, const int step) {
  const int i = excavation_of[t];
  return i >= 0 && excavation_factor(excavation_time, i, (real)step * dt) < (real)1;
}
#else
#define EXCAV_ARGS
#define EXCAV_PASS
#endif

#ifdef PRELISTED
// Couples listed ahead of their triangles' joins (activation "fractured" with a skin,
// ContactDetection's LIST_INACTIVE): `active` tells which triangles take part now.
#define PRELIST_ARGS , __global const uint *restrict active
#define PRELIST_PASS , active
#else
#define PRELIST_ARGS
#define PRELIST_PASS
#endif

// Couple c: true when it may overlap (for the list); otherwise it is done here. The two
// triangles of an intact or closed CE4 are not a contact couple: the CE4 carries their
// overlap and sliding (its compression branch and friction element; cohesive_forces.cl).
// Nor are two triangles that meet at a corner of a bonded fan whose CE4s are all intact:
// the fan holds them (under compression their corners overlap by the CE4s' own
// compliance, as the faces of an intact CE4 do).
__attribute__((always_inline)) inline bool classify_couple(const uint c, __global const ulong* keys, const uint n_previous,
                            __global const ulong* previous_keys, __global const real* previous_history,
                            __global real* history, __global const uint* tri_nodes, __global const real2* position,
                            const real energy_scale, __global long* energy, const uint same_list,
                            const uint new_from, __global uchar* live, __global uint* slot,
                            __global const uint* carry_of BOND_ARGS CLASSIFY_BOND_ARGS PRELIST_ARGS EXCAV_ARGS AWAKE_ARGS) {
  // A new list, or couples appended to this one from `new_from` on (triangles that joined
  // the candidates, ContactDetection::extend_joined): no pool row, no flag yet.
  const bool fresh = !same_list || c >= new_from;
  if (fresh) slot[c] = NO_SLOT;
#ifdef EXCAVATION
  {
    const ulong key = keys[c];
    if (excavated_triangle((uint)(key >> 32), excavation_of, excavation_time, excavation_dt, excavation_step) ||
        excavated_triangle((uint)(key & 0xffffffffUL), excavation_of, excavation_time, excavation_dt,
                           excavation_step)) {
      if (fresh || live[c]) {
        const int found = same_list ? pool_row(c, slot) : carried_row(c, carry_of);
        forget_couple(same_list ? found : -1, found, previous_history, history, energy_scale, energy, true);
        live[c] = 0;
      }
      return false;
    }
  }
#endif
#ifdef CE4_BONDS
  // Most candidate couples of intact rock are carried by a CE4 or a bonded fan: with the
  // list's bond words known, such a couple costs two words read, not the key and the
  // gathers through bond_ce4, tri_nodes and node_origin that found its bond.
  uint word;
  if (c < bond_words_known) {
    word = bond_word[c];
  } else {
    const ulong key = keys[c];
#ifdef CORNER_FANS
    word = couple_bond((uint)(key >> 32), (uint)(key & 0xffffffffUL), bond_ce4, tri_nodes, node_origin);
#else
    word = couple_bond((uint)(key >> 32), (uint)(key & 0xffffffffUL), bond_ce4, tri_nodes);
#endif
    bond_word[c] = word;
  }
#ifdef CORNER_FANS
  const int bond = bond_word_state(word, ce4_status, mesh_node_state);
#else
  const int bond = bond_word_state(word, ce4_status);
#endif
  // A CE4 intact (0) or closed (1), or a whole fan (0; a fan's state is never 1).
  const bool carried_by_ce4 = bond == 0 || bond == 1;
#ifdef SLEEPERS
  *unbonded = !carried_by_ce4;
#endif
#else
  const bool carried_by_ce4 = false;
#endif
  if (!carried_by_ce4) {
    const ulong key = keys[c];
#ifdef PRELISTED
    // Not a couple until both of its triangles take part (listed ahead of a join): asked
    // before the nodes' positions are gathered, which most such couples never need.
    const bool both_take_part = active[(uint)(key >> 32)] != 0u && active[(uint)(key & 0xffffffffUL)] != 0u;
#else
    const bool both_take_part = true;
#endif
    if (both_take_part) {
      uint tri[2], nodes[2][3];
      real2 x[2][3];
      couple_nodes(key, tri_nodes, position, tri, nodes, x);
      if (!separated(x)) return true;
    }
  }
  if (fresh || live[c]) {  // in place and already forgotten: nothing to read or write
    const int found = same_list ? pool_row(c, slot) : carried_row(c, carry_of);
    forget_couple(same_list ? found : -1, found, previous_history, history, energy_scale, energy, false);
    live[c] = 0;
  }
  return false;
}

// One work-item per candidate couple c: the cheap separation test. Separated couples are
// done here (forget_couple); the others are appended to `overlap_list` for
// contact_forces, so that its work-items all do the full evaluation together instead of
// idling beside separated neighbours. The list's order depends on scheduling, but what
// contact_forces does per couple does not, and its sums are integer: the result does not.
// counters[list_counter]: entries in overlap_list. The two counters alternate from one
// launch to the next (ContactForces flips list_counter): work-item 0 zeroes the other,
// which the next step counts in, so no launch of its own clears them.
// The step's start, done here to save a launch: work-item i < n_nodes zeroes node i's
// fixed-point contact force (contact_forces adds into it after this kernel; it is read
// for the node's force and for output after the step), and with POOL_MONITOR (a contact
// skin) work-item 0 copies the history pool's rows taken so far to word RING_POOL of this
// step's monitor ring slot, where the host reads it late and grows the pool before it
// fills (ContactForces::ensure_pool). The launch covers max(n_couples, n_nodes) items.
// bond_word[c] (with CE4s): couple c's couple_bond, written in the first step of a list
// (bond_words_known = 0; also after a checkpoint is loaded; the first step after an
// extension writes those of the appended couples, bond_words_known = new_from) and read
// for couples c < bond_words_known.
// live[c]: 1 when couple c touched in the last step, 2 when it overlaps but waits (see
// contact_forces), 0 otherwise (written by both kernels; read in
// place, to skip the history of couples that are apart and already forgotten; the host
// counts them for the number of touching couples).
// On GPUs the list grows by one global atomic per work-group (a local count first: one
// global counter hit by every overlapping couple would serialise them); CPU devices
// (CONTACT_SUM_PER_COUPLE) have few threads and take the plain counter, without barriers.
// SLEEPERS (a model with CE4s, no excavation): a couple that a bond carries and that is
// not live does nothing here, and stays so until some CE4's status changes (a bond
// breaks or lets go: the only way a couple stops being carried). A full classification
// visits every couple and lists those no bond carries in `awake`; a lean one visits only
// those (work-item k takes couple awake[k]). Full when the host asks (`full_forced`: a
// new or extended list, bond words not yet known), when cohesive_forces changed a status
// in the step before (`ce4_status_step[0] == step`: it writes its step + 1), and when
// the last full one found more awake couples than `awake_capacity`. awake_count holds
// three counts that rotate with the launches (`rotation` = this launch's slot): a full
// classification counts into its slot (zeroed by the launch before, or by the host when
// it forces one), a lean one copies the previous slot's count into its own, and either
// zeroes the next one, which no work-item of this launch reads. awake_count[3] counts the
// lean launches.
__kernel void contact_classify(const uint n_couples,
                               __global const ulong* restrict keys,
                               const uint n_previous,
                               __global const ulong* restrict previous_keys,
                               __global const real* previous_history,
                               __global real* history,
                               __global const uint* restrict tri_nodes,
                               __global const real2* restrict position,
                               const real energy_scale,
                               __global long* restrict energy,
                               const uint same_list,
                               const uint new_from,
                               __global uint* restrict counters,
                               __global uint* restrict overlap_list,
                               __global uchar* restrict live,
                               __global uint* restrict slot,
                               __global const uint* restrict carry_of BOND_ARGS CLASSIFY_BOND_ARGS PRELIST_ARGS,
                               const uint n_nodes,
                               __global long* restrict contact_acc,
                               const uint list_counter
#ifdef POOL_MONITOR
                               , __global const uint* restrict pool_state, __global uint* restrict monitor,
                               const uint monitor_slot
#endif
#ifdef SLEEPERS
                               , const uint full_forced, __global const int* restrict ce4_status_step, const int step,
                               __global uint* restrict awake, __global uint* restrict awake_count,
                               const uint rotation, const uint awake_capacity
#endif
                               EXCAV_ARGS) {
  const uint k = get_global_id(0);
#ifdef SLEEPERS
  const uint awake_before = awake_count[(rotation + 2u) % 3u];
  const bool full = full_forced != 0u || ce4_status_step[0] == step || awake_before > awake_capacity;
  const uint c = full ? k : k < awake_before ? awake[k] : n_couples;
#else
  const uint c = k;
#endif
  if (k == 0) {
    counters[1u - list_counter] = 0;
#ifdef POOL_MONITOR
    monitor[RING_WORDS * monitor_slot + RING_POOL] = pool_state[0];
#endif
#ifdef SLEEPERS
    if (!full) {
      awake_count[rotation] = awake_before;
      awake_count[3] += 1u;  // lean launches so far (for tests and the profile)
    }
    awake_count[(rotation + 1u) % 3u] = 0;
#endif
  }
  if (k < n_nodes) {
    contact_acc[2 * k] = 0;
    contact_acc[2 * k + 1] = 0;
  }
#ifdef SLEEPERS
  bool unbonded = false;
#ifdef CONTACT_SUM_PER_COUPLE
  __local uchar group_unbonded[GROUP_SIZE];
#else
  __local uint group_awake, group_awake_base;
#endif
#endif
#ifdef CONTACT_SUM_PER_COUPLE
  if (c < n_couples && classify_couple(c, keys, n_previous, previous_keys, previous_history, history, tri_nodes,
                                       position, energy_scale, energy, same_list, new_from, live, slot, carry_of BOND_PASS CLASSIFY_BOND_PASS PRELIST_PASS EXCAV_PASS AWAKE_PASS))
    overlap_list[atomic_inc(&counters[list_counter])] = c;
#ifdef SLEEPERS
  // The awake list of a full classification (where c = k): each work-item's flag in local
  // memory, then the group's first work-item appends the group's couples with one global
  // atomic (one per couple would keep the cores' caches fighting over the counter). Only
  // local memory crosses the barrier: PoCL 3 has kept the group's last work-item's
  // private value for all across barriers (docs/performance-notes.md, session 11).
  // (The barrier is met in lean launches too: PoCL's work-group loops crashed on one
  // inside a branch, although the branch is the same for the whole launch.)
  group_unbonded[get_local_id(0)] = c < n_couples && unbonded ? 1 : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (full) {
    if (get_local_id(0) == 0) {
      const uint size = get_local_size(0), first = get_group_id(0) * size;
      uint found = 0;
      for (uint l = 0; l < size; ++l) found += group_unbonded[l];
      uint at = found ? atomic_add(&awake_count[rotation], found) : 0u;
      for (uint l = 0; l < size && found; ++l)
        if (group_unbonded[l] && at < awake_capacity) awake[at++] = first + l;
    }
  }
#endif
#else
  __local uint group_count, group_base;
  // SLEEPERS: the awake list of a full classification grows the same way, in the same
  // barriers (met by every work-item whether the launch is full or lean).
  if (get_local_id(0) == 0) {
    group_count = 0;
#ifdef SLEEPERS
    group_awake = 0;
#endif
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  const bool listed = c < n_couples && classify_couple(c, keys, n_previous, previous_keys, previous_history, history,
                                                       tri_nodes, position, energy_scale, energy, same_list,
                                                       new_from, live, slot, carry_of BOND_PASS CLASSIFY_BOND_PASS PRELIST_PASS EXCAV_PASS AWAKE_PASS);
  const uint position_in_group = listed ? atomic_inc(&group_count) : 0u;
#ifdef SLEEPERS
  const bool append = full && c < n_couples && unbonded;
  const uint awake_in_group = append ? atomic_inc(&group_awake) : 0u;
#endif
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) {
    group_base = atomic_add(&counters[list_counter], group_count);
#ifdef SLEEPERS
    group_awake_base = group_awake ? atomic_add(&awake_count[rotation], group_awake) : 0u;
#endif
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (listed) overlap_list[group_base + position_in_group] = c;
#ifdef SLEEPERS
  if (append && group_awake_base + awake_in_group < awake_capacity) awake[group_awake_base + awake_in_group] = c;
#endif
#endif
}

// Pass p = 3 dir + e as the last step's friction force acted on it: from the positions
// of the last step, x − v Δt (v: the velocities of the move from there to x), its acting
// point, barycentric weights and tangent, and so its spring's stiffness `k_prev` and the
// relative move `move` along it over the step that the last force did work on. No memory:
// the geometry is rebuilt (for couples whose springs hold a slip only).
inline void old_spring(real2 xo[2][3], real lvo[2][3][3], real2 v[2][3], const int dir, const int e,
                       const real round_off, const real k_per_length, const real dt, real* k_prev, real* move) {
  const int B = 1 - dir;
  real l0[3], l1[3], I0, I1, inside;
  for (int m = 0; m < 3; ++m) {
    l0[m] = lvo[dir][e][m];
    l1[m] = lvo[dir][(e + 1) % 3][m];
  }
  integrate_potential(l0, l1, round_off, &I0, &I1, &inside);
  const real I = I0 + I1;
  const real s = I > (real)0 ? I1 / I : (real)0.5;  // I > 0 but for rounding: the pass held a force
  const real2 edge = xo[dir][(e + 1) % 3] - xo[dir][e];
  const real L = length(edge);
  real2 vB = (real2)(0, 0);
  for (int m = 0; m < 3; ++m)
    vB += ((1 - s) * lvo[dir][e][(m + 1) % 3] + s * lvo[dir][(e + 1) % 3][(m + 1) % 3]) / (real)3 * v[B][m];
  const real2 vA = (1 - s) * v[dir][e] + s * v[dir][(e + 1) % 3];
  *k_prev = k_per_length * L;
  *move = dot(vA - vB, edge / L) * dt;
}

// Rounding of the couple's barycentric values l: coordinates carry ε|x|, so the cross
// products behind l (3 A_m / A) are off by about ε |x| h / A ≈ 3 ε |x| / h; 64 times that.
inline real couple_round_off(real2 x[2][3]) {
  real reach = (real)0, smallest = INFINITY;
  for (int k = 0; k < 2; ++k) {
    for (int a = 0; a < 3; ++a) reach = fmax(reach, fmax(fabs(x[k][a].x), fabs(x[k][a].y)));
    const real2 u = x[k][1] - x[k][0], w = x[k][2] - x[k][0];
    smallest = fmin(smallest, fabs(u.x * w.y - u.y * w.x));
  }
#ifdef FDEM_DOUBLE
  return (real)64 * DBL_EPSILON * reach / sqrt(smallest);
#else
  return (real)64 * FLT_EPSILON * reach / sqrt(smallest);
#endif
}

// Edge pass p = 3 dir + e (edge e of triangle A = dir, inside triangle B = 1 − dir): the
// potential of B integrated along the edge, split by the lever rule (I0, I1), and the
// fraction of the edge inside B. The barycentric weights (×3) of B's vertex q at the ends
// of A's edge e are lv[dir][e][(q + 1) % 3] and lv[dir][(e + 1) % 3][(q + 1) % 3].
inline void pass_integrals(const int dir, const int e, real lv[2][3][3], const real round_off, real* I0, real* I1,
                           real* inside) {
  real l0[3], l1[3];
  for (int m = 0; m < 3; ++m) {
    l0[m] = lv[dir][e][m];
    l1[m] = lv[dir][(e + 1) % 3][m];
  }
  integrate_potential(l0, l1, round_off, I0, I1, inside);
}

// The couple's normal force before damping (P_n t Σ L ∫φ) and the length of its edges
// inside the other triangle, summed over the passes in order.
inline void normal_totals(real2 x[2][3], const real I0[6], const real I1[6], const real inside[6], const real Pn,
                          const real thickness, real* normal_total, real* contact_length) {
  real total = 0, inside_length = 0;
  for (int dir = 0; dir < 2; ++dir)
    for (int e = 0; e < 3; ++e) {
      const int p = 3 * dir + e;
      const real L = length(x[dir][(e + 1) % 3] - x[dir][e]);
      total += Pn * thickness * L * (I0[p] + I1[p]);
      inside_length += inside[p] * L;
    }
  *normal_total = total;
  *contact_length = inside_length;
}

// An-Tannant damping (Eq. 15): the ratio σ/σ_try that scales the couple's normal force;
// loading raises hist[HIST_OVERLAP_MAX].
inline real damping_ratio(real hist[CONTACT_HISTORY], const real normal_total, const real contact_length,
                          const real thickness, const real Pn, const real T, const real b) {
  const real area = (real)0.5 * contact_length * thickness;       // contact area A_con
  const real sigma_try = normal_total / area;
  const real overlap = sigma_try / Pn;                            // nominal overlap o_n (mean potential)
  real sigma;
  if (overlap >= hist[HIST_OVERLAP_MAX]) {  // loading
    sigma = fmin(sigma_try, T);
    hist[HIST_OVERLAP_MAX] = overlap;
  } else {                                  // unloading, from σ_peak = min(P_n o_n_max, T)
    sigma = fmin(Pn * hist[HIST_OVERLAP_MAX], T) * pow(overlap / hist[HIST_OVERLAP_MAX], b);
  }
  return sigma / sigma_try;
}

// Damped couple: force = ratio × (−∇E). The work done on it over the last step, by the
// trapezoid rule ½ (ratio_prev + ratio)(E − E_prev), is held. Unloading (Eq. 15) only
// lowers the ratio, so the couple can give back at most ratio × E; held work above that
// is dissipated now. The dissipation so never decreases, held + dissipated is exactly the
// work done, and what is still held when the couple lets go is dissipated then. A new
// couple starts from E = 0. *stored: what it holds; *damping_lost: whole units of the
// accumulator dissipated now (the rest stays held, dissipated later or at release).
inline void damped_work(real hist[CONTACT_HISTORY], const real ratio, const real elastic, const real energy_scale,
                        real* stored, real* damping_lost) {
  const real e_prev = hist[HIST_ENERGY];
  const real r_prev = e_prev > (real)0 ? hist[HIST_RATIO] : ratio;
  real held = hist[HIST_HELD] + (real)0.5 * (r_prev + ratio) * (elastic - e_prev);
  const real branch = ratio * elastic;
  real lost = (real)0;
  if (held > branch) {
    lost = held - branch;
    held = branch;
  }
  const real booked = (real)convert_long_rte(lost * energy_scale) / energy_scale;
  held += lost - booked;
  hist[HIST_ENERGY] = elastic;
  hist[HIST_RATIO] = ratio;
  hist[HIST_HELD] = held;
  *stored = held;
  *damping_lost = booked;
}

// The rest of the exact gradient of E (see the note at couple_potential): on each
// triangle k, −(E_k / A_k) ∂A_k/∂x_a = (E_k / 2A_k) × (outward normal × length of the
// edge opposite vertex a). Zero net force and moment on each triangle. It rides along
// with the first pass that writes all three of the triangle's vertices (as B), so it
// costs no extra atomics there.
inline void area_forces(real2 x[2][3], const real ratio, const real Pn, const real thickness, const real potential[2],
                        real2 area_force[2][3]) {
  for (int q = 0; q < 2; ++q) {
    const real twice_area = (x[q][1].x - x[q][0].x) * (x[q][2].y - x[q][0].y) - (x[q][1].y - x[q][0].y) * (x[q][2].x - x[q][0].x);
    const real coeff = ratio * Pn * thickness * potential[q] / twice_area;
    for (int a = 0; a < 3; ++a) {
      const real2 e = x[q][(a + 2) % 3] - x[q][(a + 1) % 3];
      area_force[q][a] = coeff * (real2)(e.y, -e.x);
    }
  }
}

// What edge_pass did (bits of its result).
#define PASS_ACTS 1    // its integral is positive: fA0, fA1, fB hold its forces
#define PASS_LOST 2    // *lost adds to the couple's friction dissipation
#define PASS_SPRING 4  // *pending and *spring (its slip spring's energy) add to the couple's

// Edge pass p = 3 dir + e of a couple that overlaps, its integrals I0, I1 given: the new
// slip of its spring (*slip; `previous` the last step's), its normal force on A's edge
// nodes by the lever rule (fA0, fA1) and, opposite, on B's nodes by their barycentric
// weights (fB), its friction (Eq. 16: an elastic slip at the normal force's acting point
// s*, returned to the Coulomb cap μ F_n), and its energy terms. kn: the damped normal
// force per unit ∫φ ds. xo, lvo: the last step's geometry (filled where a spring holds a
// slip). The couple's sums of the terms are taken by the caller in pass order.
inline int edge_pass(const int dir, const int e, real2 x[2][3], real lv[2][3][3], real2 v[2][3], real2 xo[2][3],
                     real lvo[2][3][3], const real I0, const real I1, const real kn, const real mu, const real Ptan,
                     const real thickness, const real dt, const real round_off, const bool friction,
                     const real previous, real* slip_out, real* lost, real* pending, real* spring, real2* fA0,
                     real2* fA1, real2 fB[3]) {
  const int A = dir, B = 1 - dir;
  const real I = I0 + I1;
  const real2 pa = x[A][e], pb = x[A][(e + 1) % 3];
  const real2 edge = pb - pa;
  const real L = length(edge);
  const real2 tangent = edge / L;
  const real stiffness = Ptan * L * thickness;  // the slip spring: whole edge (header note)
  *slip_out = (real)0;
  if (!(I > (real)0)) {
    // The pass let go: its spring's energy and the half step of work its last force
    // does (trapezoid rule, the force ending at zero) are dissipated.
    if (friction && previous != (real)0) {
      real k_prev, move;
      old_spring(xo, lvo, v, dir, e, round_off, Ptan * thickness, dt, &k_prev, &move);
      *lost = (real)0.5 * k_prev * previous * (previous + move);
      return PASS_LOST;
    }
    return 0;
  }
  const real2 nL = (real2)(edge.y, -edge.x);  // outward normal × L
  *fA0 = -kn * I0 * nL;
  *fA1 = -kn * I1 * nL;
  for (int m = 0; m < 3; ++m) fB[m] = kn * (lv[dir][e][(m + 1) % 3] * I0 + lv[dir][(e + 1) % 3][(m + 1) % 3] * I1) / (real)3 * nL;
  if (!friction) return PASS_ACTS;
  const real s = I1 / I;
  real wB[3];
  for (int m = 0; m < 3; ++m) wB[m] = ((1 - s) * lv[dir][e][(m + 1) % 3] + s * lv[dir][(e + 1) % 3][(m + 1) % 3]) / (real)3;
  const real2 vA = (1 - s) * v[A][e] + s * v[A][(e + 1) % 3];
  const real2 vB = wB[0] * v[B][0] + wB[1] * v[B][1] + wB[2] * v[B][2];
  const real step_slip = dot(vA - vB, tangent) * dt;  // relative move over the last step
  const real cap = mu * kn * L * I;
  const real trial = previous + step_slip;
  const real slip = stiffness * fabs(trial) > cap ? cap / stiffness * sign(trial) : trial;
  // Dissipated over the last step: the spring's work by the trapezoid rule, each force
  // with the move it did work on, less the change of its energy ½ k s².
  real last_work = (real)0;  // ½ k_prev s_prev (Δs_prev + s_prev)
  if (previous != (real)0) {
    real k_prev, move;
    old_spring(xo, lvo, v, dir, e, round_off, Ptan * thickness, dt, &k_prev, &move);
    last_work = (real)0.5 * k_prev * previous * (previous + move);
  }
  *lost = last_work + (real)0.5 * stiffness * slip * (step_slip - slip);
  // What it dissipates if it lets go before the next step: its energy and the half step
  // of work of its last force (the next step's move estimated by this one's).
  *pending = (real)0.5 * stiffness * slip * (slip + step_slip);
  *spring = (real)0.5 * stiffness * slip * slip;
  *slip_out = slip;
  const real2 f = -stiffness * slip * tangent;
  *fA0 += (1 - s) * f;
  *fA1 += s * f;
  for (int m = 0; m < 3; ++m) fB[m] -= wB[m] * f;
  return PASS_ACTS | PASS_LOST | PASS_SPRING;
}

// Whether an overlapping couple waits without force (its history then marked): a new
// couple found overlapping because one of its triangles joined contact (activation
// "fractured": its mask value, the join's stamp, is at least `joined_since`: this step's
// stamp when couples are listed ahead of joins (PRELISTED), else the first stamp after
// the last detection), next to a triangle it already overlapped at a corner: its potential
// was never paid for by any work, so it stays without force or energy, marked by
// HIST_OVERLAP_MAX < 0, until its triangles part (the separation test or normal_total ≤ 0
// clears the history); then it is an ordinary couple (docs/energy-notes.md). Couples that
// approached (both triangles in contact before) push at once as always. Likewise the two
// triangles of a CE4 released in the last step (the CE4 stage runs after this one in a
// step) that still overlap: the CE4 held that overlap's energy (and dissipated it when it
// let go), the contact potential there was never paid for.
inline bool waits_unpaid(const uint c, const uint tri[2], const int found, const real overlap_max,
                         __global const uint* active, const uint joined_since, const uint same_list,
                         const uint new_from, __global const uint* tri_nodes, const int step BOND_ARGS) {
  const bool joined = active[tri[0]] >= joined_since || active[tri[1]] >= joined_since;
#ifdef CE4_BONDS
  const int bond = bond_state(tri[0], tri[1], bond_ce4, ce4_status);
#ifdef CORNER_FANS
  // (or a corner couple whose fan lost its first CE4 in the last step)
  const bool released_now =
      bond == step + 1 || (bond < 0 && corner_state(tri[0], tri[1], tri_nodes, node_origin, mesh_node_state) == step + 1);
#else
  const bool released_now = bond == step + 1;  // 2 + (step − 1)
#endif
#else
  const bool released_now = false;
#endif
#ifdef PRELISTED
  // Listed ahead of the join (joined_since is this step's stamp): met overlapping in the
  // very step its triangle joined, whichever list it is in.
  const bool met_over_overlap = found < 0 && joined;
#else
  // (couples appended to the list in this step are new too: c >= new_from)
  const bool met_over_overlap = found < 0 && (!same_list || c >= new_from) && joined;
#endif
  return met_over_overlap || released_now || overlap_max < (real)0;
}

// A couple that waits unpaid (waits_unpaid): its history row holds only the mark.
inline void mark_unpaid(const uint c, __global uint* slot, __global uint* pool_state, const uint pool_capacity,
                        const int step, __global real* history, __global uchar* live) {
  const int row = take_slot(c, slot, pool_state, pool_capacity, step);
  if (row >= 0)
    for (int h = 0; h < CONTACT_HISTORY; ++h) history[CONTACT_HISTORY * row + h] = h == HIST_OVERLAP_MAX ? (real)-1 : (real)0;
  live[c] = 2;  // not touching, but its history holds the mark: classify must clear it when they part
}

// The end of an acting couple's step, its passes' sums taken: the friction dissipation
// booked in whole units (the rest carried in HIST_REST, see ENERGY_FRICTION), the history
// written to the couple's pool row, its stored energy on energy rows (each couple writes
// its own row's entry, summed in couple order by contact_stored_partials: a double sum in
// a fixed order, not 2⁻³² J per couple) and the damping's whole units. Signed increments:
// each is the exact balance of its step, so the sums close the account; they are ≥ 0 but
// for rounding and one-step reversals.
inline void finish_couple(const uint c, real hist[CONTACT_HISTORY], const real friction_lost, const real pending,
                          const real stored, const real damping_lost, const real energy_scale,
                          __global long* energy, __global uint* slot, __global uint* pool_state,
                          const uint pool_capacity, const int step, __global real* history, __global uchar* live,
                          const uint energy_row, __global real* couple_stored) {
  hist[HIST_PENDING] = pending;
  const real unbooked = friction_lost + hist[HIST_REST];
  const long friction_units = convert_long_rte(unbooked * energy_scale);
  hist[HIST_REST] = unbooked - (real)friction_units / energy_scale;
  const int row = take_slot(c, slot, pool_state, pool_capacity, step);
  if (row >= 0)
    for (int h = 0; h < CONTACT_HISTORY; ++h) history[CONTACT_HISTORY * row + h] = hist[h];
  live[c] = 1;
  if (energy_row && row >= 0) couple_stored[row] = stored;
  if (friction_units != 0) atom_add(&energy[ENERGY_FRICTION], friction_units);
  if (damping_lost != (real)0) atom_add(&energy[ENERGY_DAMPING], convert_long_rte(damping_lost * energy_scale));
}

#define CONTACT_FORCES_ARGS                                                                                        \
  const uint n_couples, __global const ulong *restrict keys, const uint n_previous,                                \
      __global const ulong *restrict previous_keys, __global const real *previous_history, __global real *history, \
      __global const uint *restrict tri_nodes, __global const uint *restrict tri_material, const uint n_materials, \
      __global const uint *restrict pair_index, __global const real *restrict pair_props,                          \
      __global const real2 *restrict position, __global const real2 *restrict velocity, const real thickness,      \
      const real dt, const real force_scale, const real energy_scale, __global long *restrict contact_acc,         \
      __global long *restrict energy, __global uint *restrict counters, const uint same_list, const uint new_from, \
      __global const uint *restrict overlap_list, __global uchar *restrict live, __global uint *restrict slot,     \
      __global const uint *restrict carry_of, __global uint *restrict pool_state, const uint pool_capacity,        \
      const uint energy_row, __global real *restrict couple_stored, __global const uint *restrict active,          \
      const uint joined_since, const int step BOND_ARGS, const uint list_counter

#define CONTACT_FORCES_PASS                                                                                      \
  n_couples, keys, n_previous, previous_keys, previous_history, history, tri_nodes, tri_material, n_materials,    \
      pair_index, pair_props, position, velocity, thickness, dt, force_scale, energy_scale, contact_acc, energy,  \
      counters, same_list, new_from, overlap_list, live, slot, carry_of, pool_state, pool_capacity, energy_row,   \
      couple_stored, active, joined_since, step BOND_PASS, list_counter

// The full evaluation of couple c by one work-item.
inline void contact_couple(const uint c, CONTACT_FORCES_ARGS) {
  uint tri[2], nodes[2][3];
  real2 x[2][3];
  real lv[2][3][3];
  couple_nodes(keys[c], tri_nodes, position, tri, nodes, x);
  barycentric_values(x, lv);
  __global const real* props =
      pair_props + CONTACT_PROPS * pair_index[tri_material[tri[0]] * n_materials + tri_material[tri[1]]];
  const real Pn = props[PAIR_NORMAL_PENALTY], Ptan = props[PAIR_TANGENTIAL_PENALTY], mu = props[PAIR_FRICTION],
             T = props[PAIR_TENSILE], b = props[PAIR_DAMPING];
  const int damped = props[PAIR_DAMPED] != (real)0;

  // The row of the couple's history in previous_history (the pool itself in the same
  // list, the carry list in a new one), -1: none (zero).
  const int found = same_list ? pool_row(c, slot) : carried_row(c, carry_of);

  real I0[6], I1[6], inside[6];
  const real round_off = couple_round_off(x);
  for (int dir = 0; dir < 2; ++dir)
    for (int e = 0; e < 3; ++e) pass_integrals(dir, e, lv, round_off, &I0[3 * dir + e], &I1[3 * dir + e], &inside[3 * dir + e]);
  real normal_total, contact_length;
  normal_totals(x, I0, I1, inside, Pn, thickness, &normal_total, &contact_length);
  if (normal_total <= (real)0) {  // no overlap after all
    forget_couple(same_list ? found : -1, found, previous_history, history, energy_scale, energy, false);
    live[c] = 0;
    return;
  }
  real hist[CONTACT_HISTORY];
  for (int h = 0; h < CONTACT_HISTORY; ++h) hist[h] = found >= 0 ? previous_history[CONTACT_HISTORY * found + h] : (real)0;
  if (waits_unpaid(c, tri, found, hist[HIST_OVERLAP_MAX], active, joined_since, same_list, new_from, tri_nodes,
                   step BOND_PASS)) {
    mark_unpaid(c, slot, pool_state, pool_capacity, step, history, live);
    return;
  }
  real2 v[2][3];
  for (int k = 0; k < 2; ++k)
    for (int a = 0; a < 3; ++a) v[k][a] = velocity[nodes[k][a]];
#ifdef CONTACT_SUM_PER_COUPLE
  real2 fnode[2][3];
  for (int k = 0; k < 2; ++k)
    for (int a = 0; a < 3; ++a) fnode[k][a] = (real2)(0, 0);
#endif

  const real ratio = damped ? damping_ratio(hist, normal_total, contact_length, thickness, Pn, T, b) : (real)1;
  // The couple's potential energy E = P_n t ∫_{c∩t}(φ_c + φ_t) dA, per triangle's φ.
  real potential[2];
  couple_potential(x, I0, I1, inside, potential);
  const real elastic = Pn * thickness * (potential[0] + potential[1]);
  real stored = elastic, damping_lost = (real)0;
  if (damped) damped_work(hist, ratio, elastic, energy_scale, &stored, &damping_lost);
#ifdef EXCAVATION
  else hist[HIST_ENERGY] = elastic;  // what an excavation that stops the couple books (forget_couple)
#endif
  real2 area_force[2][3];
  area_forces(x, ratio, Pn, thickness, potential, area_force);
  bool area_due[2] = {true, true};

  const bool friction = mu != (real)0 && Ptan != (real)0;
  const real kn = ratio * Pn * thickness;  // normal force per unit ∫φ ds
  real friction_lost = (real)0, pending = (real)0;
  // The last step's positions and barycentric values, for the work of the last step's
  // friction forces (old_spring); only where a spring holds a slip.
  real2 xo[2][3];
  real lvo[2][3][3];
  bool slipped = false;
  for (int p = 0; p < 6; ++p) slipped = slipped || hist[p] != (real)0;
  if (friction && slipped) {
    for (int k = 0; k < 2; ++k)
      for (int a = 0; a < 3; ++a) xo[k][a] = x[k][a] - v[k][a] * dt;
    barycentric_values(xo, lvo);
  }
  for (int dir = 0; dir < 2; ++dir) {
    const int A = dir, B = 1 - dir;
    for (int e = 0; e < 3; ++e) {
      const int p = 3 * dir + e;
      real lost, pend, spring;
      real2 fA0, fA1, fB[3];
      const int did = edge_pass(dir, e, x, lv, v, xo, lvo, I0[p], I1[p], kn, mu, Ptan, thickness, dt, round_off,
                                friction, hist[p], &hist[p], &lost, &pend, &spring, &fA0, &fA1, fB);
      if (did & PASS_LOST) friction_lost += lost;
      if (did & PASS_SPRING) {
        pending += pend;
        if (energy_row) stored += spring;
      }
      if (!(did & PASS_ACTS)) continue;
      if (area_due[B]) {
        for (int m = 0; m < 3; ++m) fB[m] += area_force[B][m];
        area_due[B] = false;
      }
      COUPLE_FORCE(A, e, fA0);
      COUPLE_FORCE(A, (e + 1) % 3, fA1);
      for (int m = 0; m < 3; ++m) COUPLE_FORCE(B, m, fB[m]);
    }
  }
  for (int q = 0; q < 2; ++q)
    if (area_due[q])
      for (int a = 0; a < 3; ++a) COUPLE_FORCE(q, a, area_force[q][a]);
#ifdef CONTACT_SUM_PER_COUPLE
  for (int k = 0; k < 2; ++k)
    for (int a = 0; a < 3; ++a) add_force(contact_acc, nodes[k][a], fnode[k][a], force_scale);
#endif
  finish_couple(c, hist, friction_lost, pending, stored, damping_lost, energy_scale, energy, slot, pool_state,
                pool_capacity, step, history, live, energy_row, couple_stored);
}

// One work-item per entry k of overlap_list (launched over all couples; those past the
// list's length return): the full evaluation of couple overlap_list[k].
__kernel void contact_forces(CONTACT_FORCES_ARGS) {
  const uint entry = get_global_id(0);
  if (entry >= n_couples || entry >= counters[list_counter]) return;
  contact_couple(overlap_list[entry], CONTACT_FORCES_PASS);
}

#ifdef CONTACT_LANES
// The same evaluation with eight work-items per couple (work-groups of 64: eight couples),
// for GPUs. There one couple's evaluation is a long chain of dependent double-precision
// steps and few couples touch (the platens of a UCS test, the pieces of a blast), so the
// stage took the chain's latency (about 80 µs on an H200, at 60k or 1M TRI3 alike) with
// most of the device idle. Lane p < 6 integrates and evaluates edge pass p (its forces go
// out at once, as in contact_forces), lane 6 the overlap's area; every lane works out
// the couple's shared values (geometry, totals, damping ratio, area forces) itself from
// the same inputs in the same order, so they agree bit for bit, and lane 0 takes the
// couple's sums over the passes in pass order, as contact_forces takes them: both kernels
// give the same bits. The work-groups stride over the overlap list (the launch covers the
// couples, as contact_forces', eight entries a group a round). The lanes repeat the
// couple's shared work, so where many couples touch (more than LANES_UP_TO, a host define
// from measurements, docs/performance-notes.md) the device is busy anyway and one
// work-item per couple is faster: the launch then does what contact_forces does.
// Narrow lanes (LANES_NARROW_FROM, a host define only where FDEM_CONTACT_LANES_NARROW_FROM
// asks for it: not yet measured on a GPU): above that many touching couples a couple gets
// LANES_NARROW lanes and lane l does tasks l, l + LANES_NARROW, ... (task p < 6 pass p, task
// 6 the area), half the repeated shared work for the same couples. Without it `lanes` is
// the constant 8 and LANE_TASKS the one task a lane the kernel always had (clang's PTX for
// that path is the earlier kernel's, but for one load's place).
#define LANES 8
#ifndef LANES_NARROW
#define LANES_NARROW 4
#endif
#ifdef LANES_NARROW_FROM
#define LANE_COUPLES (64 / LANES_NARROW)  // at most this many couples a work-group of 64
#else
#define LANE_COUPLES (64 / LANES)  // eight lanes always: `lanes` a constant (one task a lane)
#endif
__kernel __attribute__((reqd_work_group_size(64, 1, 1))) void contact_forces_lanes(CONTACT_FORCES_ARGS) {
  __local real pass_i0[LANE_COUPLES][6], pass_i1[LANE_COUPLES][6], pass_inside[LANE_COUPLES][6];
  __local real pass_lost[LANE_COUPLES][6], pass_pending[LANE_COUPLES][6], pass_spring[LANE_COUPLES][6];
  __local real pass_slip[LANE_COUPLES][6], overlap[LANE_COUPLES];
  __local int pass_did[LANE_COUPLES][6];
  const uint count = min(n_couples, counters[list_counter]);
  if (count > LANES_UP_TO) {  // the same for every work-item of the launch
    if (get_global_id(0) < count) contact_couple(overlap_list[get_global_id(0)], CONTACT_FORCES_PASS);
    return;
  }
#ifdef LANES_NARROW_FROM
  const uint lanes = count > LANES_NARROW_FROM ? LANES_NARROW : LANES;  // the same for the whole launch
#define LANE_TASKS(p) for (uint p = lane; p < 7; p += lanes)
#else
  const uint lanes = LANES;
#define LANE_TASKS(p) const uint p = lane; if (p < 7)  // one task a lane (lane 7 none)
#endif
  const uint per_group = 64 / lanes;
  const uint lane = get_local_id(0) % lanes, k = get_local_id(0) / lanes;
  for (uint base = get_group_id(0) * per_group; base < count; base += get_num_groups(0) * per_group) {
    const uint entry = base + k;
    const bool valid = entry < count;
    uint c = 0, tri[2], nodes[2][3];
    real2 x[2][3];
    real lv[2][3][3];
    real round_off = (real)0;
    if (valid) {
      c = overlap_list[entry];
      couple_nodes(keys[c], tri_nodes, position, tri, nodes, x);
      barycentric_values(x, lv);
      round_off = couple_round_off(x);
      LANE_TASKS(p) {
        if (p < 6) {
          real i0, i1, in;
          pass_integrals(p / 3, p % 3, lv, round_off, &i0, &i1, &in);
          pass_i0[k][p] = i0;
          pass_i1[k][p] = i1;
          pass_inside[k][p] = in;
        } else {
          overlap[k] = overlap_area(x);
        }
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    bool acts = false;
    real hist[CONTACT_HISTORY];
    real stored = (real)0, damping_lost = (real)0;
    if (valid) {
      real I0[6], I1[6], inside[6];
      for (int p = 0; p < 6; ++p) {
        I0[p] = pass_i0[k][p];
        I1[p] = pass_i1[k][p];
        inside[p] = pass_inside[k][p];
      }
      __global const real* props =
          pair_props + CONTACT_PROPS * pair_index[tri_material[tri[0]] * n_materials + tri_material[tri[1]]];
      const real Pn = props[PAIR_NORMAL_PENALTY], Ptan = props[PAIR_TANGENTIAL_PENALTY], mu = props[PAIR_FRICTION],
                 T = props[PAIR_TENSILE], b = props[PAIR_DAMPING];
      const int damped = props[PAIR_DAMPED] != (real)0;
      const int found = same_list ? pool_row(c, slot) : carried_row(c, carry_of);
      real normal_total, contact_length;
      normal_totals(x, I0, I1, inside, Pn, thickness, &normal_total, &contact_length);
      if (normal_total <= (real)0) {  // no overlap after all
        if (lane == 0) {
          forget_couple(same_list ? found : -1, found, previous_history, history, energy_scale, energy, false);
          live[c] = 0;
        }
      } else {
        for (int h = 0; h < CONTACT_HISTORY; ++h)
          hist[h] = found >= 0 ? previous_history[CONTACT_HISTORY * found + h] : (real)0;
        if (waits_unpaid(c, tri, found, hist[HIST_OVERLAP_MAX], active, joined_since, same_list, new_from,
                         tri_nodes, step BOND_PASS)) {
          if (lane == 0) mark_unpaid(c, slot, pool_state, pool_capacity, step, history, live);
        } else {
          acts = true;
          real2 v[2][3];
          for (int q = 0; q < 2; ++q)
            for (int a = 0; a < 3; ++a) v[q][a] = velocity[nodes[q][a]];
          const real ratio = damped ? damping_ratio(hist, normal_total, contact_length, thickness, Pn, T, b) : (real)1;
          real potential[2];
          couple_potential_of_area(x, I0, I1, overlap[k], potential);
          const real elastic = Pn * thickness * (potential[0] + potential[1]);
          stored = elastic;
          if (damped) damped_work(hist, ratio, elastic, energy_scale, &stored, &damping_lost);
#ifdef EXCAVATION
          else hist[HIST_ENERGY] = elastic;
#endif
          real2 area_force[2][3];
          area_forces(x, ratio, Pn, thickness, potential, area_force);
          const bool friction = mu != (real)0 && Ptan != (real)0;
          const real kn = ratio * Pn * thickness;
          LANE_TASKS(p) {
            if (p < 6) {
              const int dir = p / 3, e = p % 3, A = dir, B = 1 - dir;
              real2 xo[2][3];
              real lvo[2][3][3];
              if (friction && hist[p] != (real)0) {  // old_spring's geometry: this pass only needs it
                for (int q = 0; q < 2; ++q)
                  for (int a = 0; a < 3; ++a) xo[q][a] = x[q][a] - v[q][a] * dt;
                barycentric_values(xo, lvo);
              }
              real slip, lost = (real)0, pend = (real)0, spring = (real)0;
              real2 fA0, fA1, fB[3];
              const int did = edge_pass(dir, e, x, lv, v, xo, lvo, I0[p], I1[p], kn, mu, Ptan, thickness, dt,
                                        round_off, friction, hist[p], &slip, &lost, &pend, &spring, &fA0, &fA1, fB);
              pass_slip[k][p] = slip;
              pass_lost[k][p] = lost;
              pass_pending[k][p] = pend;
              pass_spring[k][p] = spring;
              pass_did[k][p] = did;
              if (did & PASS_ACTS) {
                // B's area force rides with the first acting pass of this direction.
                bool first = true;
                for (int q = 3 * dir; q < (int)p; ++q) first = first && !(I0[q] + I1[q] > (real)0);
                if (first)
                  for (int m = 0; m < 3; ++m) fB[m] += area_force[B][m];
                add_force(contact_acc, nodes[A][e], fA0, force_scale);
                add_force(contact_acc, nodes[A][(e + 1) % 3], fA1, force_scale);
                for (int m = 0; m < 3; ++m) add_force(contact_acc, nodes[B][m], fB[m], force_scale);
              }
            } else {
              // A triangle that no pass wrote as B (no acting pass of the other direction).
              for (int q = 0; q < 2; ++q) {
                bool due = true;
                for (int r = 3 * (1 - q); r < 3 * (1 - q) + 3; ++r) due = due && !(I0[r] + I1[r] > (real)0);
                if (due)
                  for (int a = 0; a < 3; ++a) add_force(contact_acc, nodes[q][a], area_force[q][a], force_scale);
              }
            }
          }
        }
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    if (acts && lane == 0) {
      real friction_lost = (real)0, pending = (real)0;
      for (int p = 0; p < 6; ++p) {
        const int did = pass_did[k][p];
        hist[p] = pass_slip[k][p];
        if (did & PASS_LOST) friction_lost += pass_lost[k][p];
        if (did & PASS_SPRING) {
          pending += pass_pending[k][p];
          if (energy_row) stored += pass_spring[k][p];
        }
      }
      finish_couple(c, hist, friction_lost, pending, stored, damping_lost, energy_scale, energy, slot, pool_state,
                    pool_capacity, step, history, live, energy_row, couple_stored);
    }
    barrier(CLK_LOCAL_MEM_FENCE);  // the next round reuses the local arrays
  }
}
#undef LANE_TASKS
#endif

// One work-item per couple of the previous list, at a new detection: a couple that is
// no longer a candidate has let go; what its friction springs held counts as dissipated
// (as forget_couple does for a couple that stops overlapping).
__kernel void release_vanished(const uint n_previous,
                               __global const ulong* restrict previous_keys,
                               __global const real* restrict previous_history,
                               const uint n_couples,
                               __global const ulong* restrict keys,
                               const real energy_scale,
                               __global long* restrict energy) {
  const uint c = get_global_id(0);
  if (c >= n_previous) return;
  const real pending = previous_history[CONTACT_HISTORY * c + HIST_PENDING] + previous_history[CONTACT_HISTORY * c + HIST_REST];
  const real held = previous_history[CONTACT_HISTORY * c + HIST_HELD];
  if ((pending != (real)0 || held != (real)0) && find_key(keys, n_couples, previous_keys[c]) < 0) {
    if (pending != (real)0) atom_add(&energy[ENERGY_FRICTION], convert_long_rte(pending * energy_scale));
    if (held != (real)0) atom_add(&energy[ENERGY_DAMPING], convert_long_rte(held * energy_scale));
  }
}

// One work-item per couple of the list (on energy rows, after contact_forces): the stored
// energy of the couples, summed over the work-group in a fixed order (group_sum4) into the
// group's slot; the host adds the slots in order. Couples that do not touch (live flag not
// 1: they wrote nothing this step) count 0; the others wrote their pool row's entry.
// Defines from the host: GROUP_SIZE (the 1D work-group size, a power of two).
__kernel void contact_stored_partials(const uint n_couples, __global const uchar* restrict live,
                                      __global const uint* restrict slot,
                                      __global const real* restrict couple_stored,
                                      __global real* restrict group_slots) {
  __local real4 scratch[GROUP_SIZE];
  const uint c = get_global_id(0);
  const uint row = c < n_couples && live[c] == 1 ? slot[c] : NO_SLOT;
  const real4 value = (real4)(row != NO_SLOT ? couple_stored[row] : (real)0, 0, 0, 0);
  const real4 sum = group_sum4(scratch, value);
  if (get_local_id(0) == 0) group_slots[get_group_id(0)] = sum.x;
}
