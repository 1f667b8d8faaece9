#include "engine/run/split_run.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/model/extrinsic.hpp"
#include "engine/model/layouts.hpp"

namespace fdem {

double default_contact_travel(const Model& model) {
  // Two mean edges (default_skin is a fraction of the mean edge), or ten skins if larger.
  return std::max(10.0 * model.contact.skin, 2.0 * default_skin(model) / kDefaultSkinFraction);
}

double contact_ghost_reach(const Model& model, double travel) {
  return (model.contact.skin + 2.0 * travel) * (1.0 + 1e-6) + 1e-300;
}

SplitRun::SplitRun(const Model& global, Transport& transport, PartitionMethod method, double travel)
    : transport_(transport), global_(global) {
  partition_ = partition_model(global, transport.size(), method);
  if (global.contact.enabled) {
    travel_ = travel > 0 ? travel : default_contact_travel(global);
    partition_.contact_reach = contact_ghost_reach(global, travel_);
  }
  local_ = fdem::local_model(global, partition_, transport.rank());
  const int rank = transport.rank();
  const auto owner = node_owners(global, partition_);
  auto set = [&](ItemKind kind, std::vector<int> global_index, size_t global_count, auto owned) {
    const int k = static_cast<int>(kind);
    scope_.owned[k].resize(global_index.size());
    for (size_t i = 0; i < global_index.size(); ++i) scope_.owned[k][i] = owned(global_index[i]) ? 1 : 0;
    scope_.global[k] = std::move(global_index);
    scope_.global_count[k] = global_count;
  };
  set(ItemKind::Node, local_.node_global, global.num_nodes(), [&](int g) { return owner[g] == rank; });
  set(ItemKind::Triangle, local_.triangle_global, global.num_triangles(),
      [&](int g) { return partition_.triangle_part[g] == rank; });
  set(ItemKind::LoadedEdge, local_.edge_global, global.loaded_edges.size(),
      [&](int g) { return owner[global.loaded_edges[g].a] == rank; });
  set(ItemKind::Ce4, local_.ce4_global, global.ce4.size(),
      [&](int g) { return partition_.triangle_part[global.ce4_triangles[g][0]] == rank; });
  scope_.transport = &transport;
}

void SplitRun::attach(ClContext& cl, Solver& solver) {
  const bool contact = global_.contact.enabled;
  halo_ = std::make_unique<HaloExchange>(cl, solver.arrays(), halo_plan(global_, partition_, local_, transport_.rank()),
                                         transport_, contact);
  solver.set_scope(&scope_);
  solver.set_strain_round_off(Solver::strain_round_off(global_));  // the account's floor: one rank's
  if (solver.has_extrinsic_stage()) {
    // Extrinsic CE4s (local_model holds every copy of each mesh node a rank owns a copy
    // of, and every extrinsic CE4 at it): the owners' integrated states before the tie,
    // so that each rank ties those nodes as one rank does, then the tied states before the
    // insertions. The insertions move no node: that second exchange is the step's last.
    solver.set_extrinsic_hooks([this] { halo_->exchange(); }, [this] { halo_->exchange(); });
    exchanged_in_step_ = true;
  }
  if (!contact) return;
  // Contact: each couple is listed by the owner of its lower triangle (the detection's
  // owned mask, Model::triangle_owned); its forces on nodes owned elsewhere travel to them
  // before the gather; the skin readings are the largest over the ranks, so every rank
  // detects at the same steps as one rank does.
  solver.set_split_hooks([this, &solver] { check_travel(solver); }, [this] { halo_->begin_contact(); },
                         [this] { halo_->finish_contact(); });
  if (ContactSkin* skin = solver.skin()) {
    skin->set_reduce([this](cl_uint* words, unsigned count) {
      constexpr int kept = 3;  // RING_MOVED, RING_SPEED, RING_JOINED (the pool word is each rank's)
      static_assert(layout::RING_MOVED < kept && layout::RING_SPEED < kept && layout::RING_JOINED < kept, "ring layout");
      std::vector<cl_uint> mine;
      for (unsigned s = 0; s < count; ++s)
        for (int w = 0; w < kept; ++w) mine.push_back(words[layout::RING_WORDS * s + w]);
      const auto all = transport_.gather(to_bytes(mine));
      std::vector<cl_uint> largest(mine.size(), 0);
      for (const auto& b : all) {
        const auto v = from_bytes<cl_uint>(b);
        for (size_t k = 0; k < largest.size(); ++k) largest[k] = std::max(largest[k], v[k]);
      }
      largest = from_bytes<cl_uint>(transport_.broadcast(to_bytes(largest)));
      for (unsigned s = 0; s < count; ++s)
        for (int w = 0; w < kept; ++w) words[layout::RING_WORDS * s + w] = largest[kept * s + w];
    });
  }
}

void SplitRun::check_travel(Solver& solver) {
  const auto x = solver.positions();
  const Model& m = local_.model;
  const auto& owned = scope_.owned[static_cast<int>(ItemKind::Node)];
  double moved = 0;
  for (size_t i = 0; i < x.size(); ++i)
    if (owned[i]) moved = std::max({moved, std::fabs(double(x[i].x) - m.x[i]), std::fabs(double(x[i].y) - m.y[i])});
  if (!(moved <= travel_)) moved = std::numeric_limits<double>::infinity();  // NaN too
  int64_t bits;
  std::memcpy(&bits, &moved, sizeof bits);  // non-negative doubles order as their bits
  const int64_t largest_bits = transport_.max(bits);
  double largest;
  std::memcpy(&largest, &largest_bits, sizeof largest);
  if (largest <= travel_) return;
  failure_agreed() = true;  // every rank stops here with the same message
  throw InputError("step " + std::to_string(solver.steps_done()) + ": a node has moved more than " +
                   format_number(travel_) + " m from its start (in x or y), the contact travel of this split run: "
                   "its contact ghost triangles no longer cover every couple. Rerun with a larger --contact-travel "
                   "(each rank then holds more ghosts) or as one process");
}

Conditions SplitRun::conditions(Solver& solver) {
  const Conditions c = solver.conditions();
  auto word = [](int v) { return v < 0 ? int64_t(INT_MAX) : int64_t(v); };
  const std::vector<int64_t> mine{
      c.bad_node < 0 ? INT_MAX : local_.node_global[c.bad_node], word(c.bad_node_step),
      c.inverted_triangle < 0 ? INT_MAX : local_.triangle_global[c.inverted_triangle], word(c.inverted_step)};
  const auto all = transport_.gather(to_bytes(mine));
  std::vector<int64_t> least(4, INT_MAX);
  for (const auto& b : all) {
    const auto v = from_bytes<int64_t>(b);
    for (int k = 0; k < 4; ++k) least[k] = std::min(least[k], v[k]);
  }
  least = from_bytes<int64_t>(transport_.broadcast(to_bytes(least)));
  auto value = [](int64_t w) { return w == INT_MAX ? -1 : static_cast<int>(w); };
  return {value(least[0]), value(least[1]), value(least[2]), value(least[3])};
}

std::vector<double> SplitRun::probe_values(Solver& solver, const std::vector<ProbeLocation>& probes) {
  if (probes.empty()) return {};
  solver.enqueue_stress();
  const auto v = solver.velocities();
  const auto s = solver.stresses();
  // Per probe, what this rank owns: (probe, 0, vx, vy) for its node, (probe, 1, sxx, syy, sxy) for its triangle.
  std::vector<double> mine;
  const int node_kind = static_cast<int>(ItemKind::Node), tri_kind = static_cast<int>(ItemKind::Triangle);
  for (size_t i = 0; i < v.size(); ++i)
    if (scope_.owned[node_kind][i])
      for (size_t k = 0; k < probes.size(); ++k)
        if (probes[k].node == scope_.global[node_kind][i]) mine.insert(mine.end(), {double(k), 0, double(v[i].x), double(v[i].y), 0});
  for (size_t t = 0; t < s.size(); ++t)
    if (scope_.owned[tri_kind][t])
      for (size_t k = 0; k < probes.size(); ++k)
        if (probes[k].triangle == scope_.global[tri_kind][t])
          mine.insert(mine.end(), {double(k), 1, double(s[t].x), double(s[t].y), double(s[t].z)});
  const auto all = transport_.gather(to_bytes(mine));
  std::vector<double> row;
  if (!root()) return row;
  row.assign(6 * probes.size(), 0.0);
  for (const auto& b : all) {
    const auto r = from_bytes<double>(b);
    for (size_t at = 0; at + 5 <= r.size(); at += 5) {
      const size_t k = static_cast<size_t>(r[at]);
      if (r[at + 1] == 0) {
        row[6 * k] = r[at + 2], row[6 * k + 1] = r[at + 3];
      } else {
        const double sxx = r[at + 2], syy = r[at + 3], sxy = r[at + 4];
        row[6 * k + 2] = sxx, row[6 * k + 3] = syy, row[6 * k + 4] = sxy;
        row[6 * k + 5] = 0.5 * (sxx + syy) + std::hypot(0.5 * (sxx - syy), sxy);  // as one rank (whole_domain.cpp)
      }
    }
  }
  return row;
}

namespace {

// The checkpoint arrays of Solver::save_state that hold one row per item (`per` rows
// per item) and the arrays that are the same on every rank. Any other name is refused
// when a split run writes or reads a checkpoint, so that an array added to a stage
// cannot be split wrongly in silence: add it here.
struct ItemArray {
  ItemKind kind;
  size_t per;
};
const std::map<std::string, ItemArray>& checkpoint_items() {
  static const std::map<std::string, ItemArray> items{
      {"position", {ItemKind::Node, 1}},
      {"velocity", {ItemKind::Node, 1}},
      {"integrate_node_work", {ItemKind::Node, 1}},
      {"edge_force", {ItemKind::LoadedEdge, 2}},
      {"load_edge_energy", {ItemKind::LoadedEdge, 1}},
      {"triangle_viscous_stress", {ItemKind::Triangle, 1}},
      {"triangle_excavation_energy", {ItemKind::Triangle, 1}},
      {"ce4_gauss_state", {ItemKind::Ce4, 3}},
      {"ce4_status", {ItemKind::Ce4, 1}},
      {"ce4_force", {ItemKind::Ce4, 4}},
      {"ce4_friction_slip", {ItemKind::Ce4, 1}},
      {"ce4_energy", {ItemKind::Ce4, 1}},
      {"ce4_excavation_energy", {ItemKind::Ce4, 1}},
      {"ce4_inserted", {ItemKind::Ce4, 1}},  // extrinsic CE4s (ce4_inserted_count: whole_count_array)
      {"ce4_insertion_gaps", {ItemKind::Ce4, 1}},
      {"contact_active", {ItemKind::Triangle, 1}},
      {"skin_position_at_build", {ItemKind::Node, 1}},
  };
  return items;
}
// Contact's arrays that are not per item (gather_contact, local_contact): the couple list
// (keys, per-couple history and live flags), the fixed-point energy words (summed over
// the ranks), the skin's ring on the device and as the host read it (words RING_MOVED,
// RING_SPEED, RING_JOINED: the largest over the ranks, which is what one rank's device
// maxima give; RING_POOL, history rows taken: the sum), the corner fans' state words per
// mesh node (each rank holds all of them; a rank's word is right where it holds every
// CE4 at the node, else 0 or a later break's: the smallest break step over the ranks) and
// the skin's host counters (the same on every rank).
bool contact_list_array(const std::string& name) {
  return name == "contact_keys" || name == "contact_history" || name == "contact_live";
}
// The skin's and the list's host counters: the same on every rank (a split run never
// extends its list by joins, so contact_extensions stays 0 there).
bool same_on_every_rank(const std::string& name) {
  return name == "skin_generations" || name == "skin_slot_steps" || name == "contact_covered_stamp" ||
         name == "contact_extensions";
}
bool contact_other_array(const std::string& name) {
  return name == "contact_energy" || name == "skin_ring" || name == "skin_ring_read" || name == "mesh_node_state" ||
         same_on_every_rank(name);
}
// Per-work-group sums (not read by the account any more; kept for the file's layout): rank 0's.
bool rank_zero_array(const std::string& name) { return name == "integrate_work" || name == "triangle_energy"; }
bool break_log_array(const std::string& name) { return name == "ce4_break_ids" || name == "ce4_break_records"; }
// The extrinsic insertions' counter: each rank's counts its ghost CE4s' insertions too, so
// the whole model's is counted from the gathered flags (gather_state); a rank reads the
// whole count back and never uses it (the history counts the gathered flags too).
bool whole_count_array(const std::string& name) { return name == "ce4_inserted_count"; }

void check_known(const std::string& name) {
  if (!checkpoint_items().count(name) && !rank_zero_array(name) && !break_log_array(name) && !whole_count_array(name) &&
      !contact_list_array(name) && !contact_other_array(name))
    throw InputError("checkpoint array '" + name + "' is not known to the split run (engine/run/split_run.cpp, "
                     "checkpoint_items): a checkpoint of this model cannot be written or read over several ranks");
}

// The break log arrays of a catalogue (CohesiveForces::save_state's layout).
void put_break_log(io::CheckpointData& data, const std::vector<io::BreakRecord>& log) {
  std::vector<cl_int> ids(2 * log.size());
  std::vector<real> rec(4 * log.size());
  for (size_t k = 0; k < log.size(); ++k) {
    ids[2 * k] = cl_int(log[k].ce4), ids[2 * k + 1] = log[k].mode;
    rec[4 * k] = real(log[k].time), rec[4 * k + 1] = real(log[k].x), rec[4 * k + 2] = real(log[k].y),
            rec[4 * k + 3] = real(log[k].energy);
  }
  data.integers["ce4_break_count"] = static_cast<std::int64_t>(log.size());
  for (auto& a : data.arrays) {
    if (a.name == "ce4_break_ids") a.bytes.assign(reinterpret_cast<const unsigned char*>(ids.data()),
                                                  reinterpret_cast<const unsigned char*>(ids.data() + ids.size()));
    if (a.name == "ce4_break_records") a.bytes.assign(reinterpret_cast<const unsigned char*>(rec.data()),
                                                      reinterpret_cast<const unsigned char*>(rec.data() + rec.size()));
  }
}

}  // namespace

namespace {
io::CheckpointArray* array_named(io::CheckpointData& data, const std::string& name) {
  for (auto& a : data.arrays)
    if (a.name == name) return &a;
  return nullptr;
}
template <class T>
std::vector<T> values_of(const io::CheckpointArray& a) {
  std::vector<T> v(a.bytes.size() / sizeof(T));
  if (!v.empty()) std::memcpy(v.data(), a.bytes.data(), v.size() * sizeof(T));
  return v;
}
template <class T>
void set_values(io::CheckpointArray& a, const std::vector<T>& v) {
  a.bytes.assign(reinterpret_cast<const unsigned char*>(v.data()), reinterpret_cast<const unsigned char*>(v.data() + v.size()));
}
}  // namespace

io::CheckpointData SplitRun::gather_state(const io::CheckpointData& local, const std::vector<io::BreakRecord>& catalogue) {
  io::CheckpointData global = local;  // attributes and rank 0's layout
  for (auto& a : global.arrays) {
    check_known(a.name);
    const auto it = checkpoint_items().find(a.name);
    if (it == checkpoint_items().end()) continue;
    const int k = static_cast<int>(it->second.kind);
    const size_t row = io::element_bytes(a.type) * a.width * it->second.per;  // bytes per item
    // (global index, row) of every owned item.
    Bytes mine;
    for (size_t i = 0; i < scope_.owned[k].size(); ++i)
      if (scope_.owned[k][i]) {
        const int64_t g = scope_.global[k][i];
        mine.insert(mine.end(), reinterpret_cast<const char*>(&g), reinterpret_cast<const char*>(&g) + sizeof g);
        mine.insert(mine.end(), a.bytes.begin() + i * row, a.bytes.begin() + (i + 1) * row);
      }
    const auto all = transport_.gather(std::move(mine));
    if (!root()) continue;
    a.bytes.assign(scope_.global_count[k] * row, 0);
    for (const auto& b : all)
      for (size_t at = 0; at + sizeof(int64_t) + row <= b.size(); at += sizeof(int64_t) + row) {
        int64_t g = 0;
        std::memcpy(&g, b.data() + at, sizeof g);
        std::memcpy(a.bytes.data() + g * row, b.data() + at + sizeof g, row);
      }
  }
  if (root() && global.find("ce4_break_ids")) put_break_log(global, catalogue);
  if (global.find("contact_keys")) gather_contact(global, local);
  if (root())
    if (io::CheckpointArray* count = array_named(global, "ce4_inserted_count"))
      if (const io::CheckpointArray* flags = global.find("ce4_inserted"))
        set_values(*count, std::vector<cl_uint>{cl_uint(count_inserted(global_, values_of<cl_int>(*flags)))});
  return global;
}

size_t count_inserted(const Model& global, const std::vector<cl_int>& inserted) {
  const auto extrinsic = extrinsic_ce4(global);
  size_t n = 0;
  for (size_t e = 0; e < extrinsic.size() && e < inserted.size(); ++e) n += extrinsic[e] && inserted[e] != 0;
  return n;
}


void SplitRun::gather_contact(io::CheckpointData& global, const io::CheckpointData& local) {
  const auto* keys_array = local.find("contact_keys");
  const auto* history_array = local.find("contact_history");
  const auto* live_array = local.find("contact_live");
  if (!keys_array || !history_array || !live_array) throw InputError("a split run's checkpoint lacks the contact list");
  const auto& tri_global = scope_.global[static_cast<int>(ItemKind::Triangle)];
  // Every couple this rank lists: (global key, history row, live flag).
  const auto keys = values_of<cl_ulong>(*keys_array);
  const auto history = values_of<real>(*history_array);
  const auto live = values_of<cl_uchar>(*live_array);
  const size_t width = history_array->width;
  if (history.size() != keys.size() * width || live.size() != keys.size())
    throw InputError("a split run's checkpoint has a contact list of mismatched lengths");
  std::vector<cl_ulong> global_keys(keys.size());
  for (size_t c = 0; c < keys.size(); ++c)
    global_keys[c] = (cl_ulong(tri_global[keys[c] >> 32]) << 32) | cl_ulong(tri_global[keys[c] & 0xffffffffu]);
  const auto all_keys = transport_.gather(to_bytes(global_keys));
  const auto all_history = transport_.gather(to_bytes(history));
  const auto all_live = transport_.gather(to_bytes(live));
  // The other contact arrays, gathered whole.
  std::map<std::string, std::vector<Bytes>> others;
  for (const auto& a : local.arrays)
    if (contact_other_array(a.name)) others[a.name] = transport_.gather(Bytes(a.bytes.begin(), a.bytes.end()));
  if (!root()) return;
  struct Couple {
    cl_ulong key;
    size_t rank, index;
  };
  std::vector<Couple> list;
  std::vector<std::vector<cl_ulong>> rank_keys(all_keys.size());
  std::vector<std::vector<real>> rank_history(all_keys.size());
  std::vector<std::vector<cl_uchar>> rank_live(all_keys.size());
  for (size_t r = 0; r < all_keys.size(); ++r) {
    rank_keys[r] = from_bytes<cl_ulong>(all_keys[r]);
    rank_history[r] = from_bytes<real>(all_history[r]);
    rank_live[r] = from_bytes<cl_uchar>(all_live[r]);
    for (size_t c = 0; c < rank_keys[r].size(); ++c) list.push_back({rank_keys[r][c], r, c});
  }
  std::sort(list.begin(), list.end(), [](const Couple& a, const Couple& b) { return a.key < b.key; });
  std::vector<cl_ulong> out_keys;
  std::vector<real> out_history;
  std::vector<cl_uchar> out_live;
  for (const auto& c : list) {
    out_keys.push_back(c.key);
    const real* h = &rank_history[c.rank][c.index * width];
    out_history.insert(out_history.end(), h, h + width);
    out_live.push_back(rank_live[c.rank][c.index]);
  }
  set_values(*array_named(global, "contact_keys"), out_keys);
  set_values(*array_named(global, "contact_history"), out_history);
  set_values(*array_named(global, "contact_live"), out_live);
  global.integers["contact_couples"] = static_cast<std::int64_t>(out_keys.size());
  for (auto& [name, parts] : others) {
    io::CheckpointArray& a = *array_named(global, name);
    if (same_on_every_rank(name)) continue;  // rank 0's: the same everywhere
    if (name == "contact_energy") {
      std::vector<cl_long> sum(a.bytes.size() / sizeof(cl_long), 0);
      for (const auto& b : parts) {
        const auto w = from_bytes<cl_long>(b);
        for (size_t k = 0; k < sum.size() && k < w.size(); ++k) sum[k] += w[k];
      }
      set_values(a, sum);
    } else if (name == "mesh_node_state") {
      auto state = values_of<cl_int>(a);
      for (const auto& b : parts) {
        const auto w = from_bytes<cl_int>(b);
        for (size_t k = 0; k < state.size() && k < w.size(); ++k)
          if (w[k] >= 2 && (state[k] < 2 || w[k] < state[k])) state[k] = w[k];
      }
      set_values(a, state);
    } else {  // skin_ring, skin_ring_read
      std::vector<cl_uint> words(a.bytes.size() / sizeof(cl_uint), 0);
      for (const auto& b : parts) {
        const auto w = from_bytes<cl_uint>(b);
        for (size_t k = 0; k < words.size() && k < w.size(); ++k)
          words[k] = k % layout::RING_WORDS == layout::RING_POOL ? words[k] + w[k] : std::max(words[k], w[k]);
      }
      set_values(a, words);
    }
  }
}

void SplitRun::local_contact(io::CheckpointData& local) const {
  auto* keys_array = array_named(local, "contact_keys");
  auto* history_array = array_named(local, "contact_history");
  auto* live_array = array_named(local, "contact_live");
  if (!keys_array || !history_array || !live_array) return;  // StateReader names what is missing
  const auto keys = values_of<cl_ulong>(*keys_array);
  const auto history = values_of<real>(*history_array);
  const auto live = values_of<cl_uchar>(*live_array);
  const size_t width = history_array->width;
  if (history.size() != keys.size() * width || live.size() != keys.size()) return;
  std::vector<int> local_of(global_.num_triangles(), -1);
  for (size_t i = 0; i < local_.triangle_global.size(); ++i) local_of[local_.triangle_global[i]] = static_cast<int>(i);
  // The couples whose lower triangle this rank owns (the ones its detection lists).
  std::vector<cl_ulong> out_keys;
  std::vector<real> out_history;
  std::vector<cl_uchar> out_live;
  for (size_t c = 0; c < keys.size(); ++c) {
    const size_t i = keys[c] >> 32, j = keys[c] & 0xffffffffu;
    if (i >= global_.num_triangles() || j >= global_.num_triangles())
      throw InputError("the checkpoint's contact list names a triangle the model does not have");
    if (partition_.triangle_part[i] != transport_.rank()) continue;
    if (local_of[j] < 0)
      throw InputError("the checkpoint's contact couple of triangles " + std::to_string(i) + " and " + std::to_string(j) +
                       " lies beyond the contact ghosts of rank " + std::to_string(transport_.rank()) +
                       ": continue it with a larger --contact-travel");
    out_keys.push_back((cl_ulong(local_of[i]) << 32) | cl_ulong(local_of[j]));
    out_history.insert(out_history.end(), history.begin() + c * width, history.begin() + (c + 1) * width);
    out_live.push_back(live[c]);
  }
  set_values(*keys_array, out_keys);
  set_values(*history_array, out_history);
  set_values(*live_array, out_live);
  local.integers["contact_couples"] = static_cast<std::int64_t>(out_keys.size());
  // The energy words: rank 0 keeps the whole model's, so the sum over the ranks is it.
  if (auto* energy = array_named(local, "contact_energy"); energy && !root())
    std::fill(energy->bytes.begin(), energy->bytes.end(), 0);
}

io::CheckpointData SplitRun::local_state(const io::CheckpointData& global) const {
  io::CheckpointData local = global;
  for (auto& a : local.arrays) {
    check_known(a.name);
    const auto it = checkpoint_items().find(a.name);
    if (it == checkpoint_items().end()) continue;
    const int k = static_cast<int>(it->second.kind);
    const size_t row = io::element_bytes(a.type) * a.width * it->second.per;
    if (a.bytes.size() != scope_.global_count[k] * row) continue;  // StateReader names the misfit
    std::vector<unsigned char> mine(scope_.global[k].size() * row);
    for (size_t i = 0; i < scope_.global[k].size(); ++i)
      std::memcpy(mine.data() + i * row, a.bytes.data() + scope_.global[k][i] * row, row);
    a.bytes = std::move(mine);
  }
  // The break log: the records of the CE4s this rank holds, with local indices, in order.
  if (const auto* ids_array = global.find("ce4_break_ids")) {
    const auto* rec_array = global.find("ce4_break_records");
    const auto it = global.integers.find("ce4_break_count");
    const size_t n = it == global.integers.end() ? 0 : static_cast<size_t>(std::max<int64_t>(0, it->second));
    if (rec_array && ids_array->bytes.size() == 2 * n * sizeof(cl_int) && rec_array->bytes.size() == 4 * n * sizeof(real)) {
      std::vector<int> local_of(global_.ce4.size(), -1);
      const int k = static_cast<int>(ItemKind::Ce4);
      for (size_t i = 0; i < scope_.global[k].size(); ++i) local_of[scope_.global[k][i]] = static_cast<int>(i);
      std::vector<io::BreakRecord> log;
      std::vector<cl_int> ids(2 * n);
      std::vector<real> rec(4 * n);
      std::memcpy(ids.data(), ids_array->bytes.data(), ids_array->bytes.size());
      std::memcpy(rec.data(), rec_array->bytes.data(), rec_array->bytes.size());
      for (size_t r = 0; r < n; ++r) {
        if (ids[2 * r] < 0 || static_cast<size_t>(ids[2 * r]) >= local_of.size() || local_of[ids[2 * r]] < 0) continue;
        io::BreakRecord b;
        b.ce4 = local_of[ids[2 * r]], b.mode = ids[2 * r + 1];
        b.time = rec[4 * r], b.x = rec[4 * r + 1], b.y = rec[4 * r + 2], b.energy = rec[4 * r + 3];
        log.push_back(b);
      }
      put_break_log(local, log);
    }
  }
  if (local.find("contact_keys")) local_contact(local);
  return local;
}

std::vector<io::BreakRecord> SplitRun::catalogue(CohesiveForces& ce4) {
  std::vector<io::BreakRecord> mine;
  for (auto b : ce4.catalogue()) {
    const int g = local_.ce4_global[b.ce4];
    if (partition_.triangle_part[global_.ce4_triangles[g][0]] != transport_.rank()) continue;
    b.ce4 = g;
    mine.push_back(b);
  }
  std::vector<io::BreakRecord> out;
  for (const auto& bytes : transport_.gather(to_bytes(mine))) {
    const auto v = from_bytes<io::BreakRecord>(bytes);
    out.insert(out.end(), v.begin(), v.end());
  }
  std::sort(out.begin(), out.end(), [](const io::BreakRecord& a, const io::BreakRecord& b) {
    return a.time != b.time ? a.time < b.time : a.ce4 < b.ce4;
  });
  return out;
}

std::vector<io::BreakRecord> SplitRun::drain_breaks(CohesiveForces& ce4) {
  std::vector<io::BreakRecord> mine;
  for (auto b : ce4.drain_breaks()) {
    const int g = local_.ce4_global[b.ce4];
    if (partition_.triangle_part[global_.ce4_triangles[g][0]] != transport_.rank()) continue;
    b.ce4 = g;
    mine.push_back(b);
  }
  const auto all = transport_.gather(to_bytes(mine));
  std::vector<io::BreakRecord> out;
  for (const auto& bytes : all) {
    const auto v = from_bytes<io::BreakRecord>(bytes);
    out.insert(out.end(), v.begin(), v.end());
  }
  std::sort(out.begin(), out.end(), [](const io::BreakRecord& a, const io::BreakRecord& b) {
    return a.time != b.time ? a.time < b.time : a.ce4 < b.ce4;
  });
  return out;
}

std::vector<int> host_fragment_labels(const Model& model, const std::vector<int>& broken) {
  // Union-find over triangles and nodes (triangles first), the root of each set its
  // smallest member.
  const size_t nt = model.num_triangles();
  std::vector<int> parent(nt + model.num_nodes());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  auto join = [&](int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  for (size_t t = 0; t < nt; ++t)
    for (int v : model.triangles[t]) join(static_cast<int>(t), static_cast<int>(nt) + v);
  for (size_t c = 0; c < model.ce4_triangles.size(); ++c)
    if (!broken[c]) join(model.ce4_triangles[c][0], model.ce4_triangles[c][1]);
  std::vector<int> labels(nt);
  for (size_t t = 0; t < nt; ++t) labels[t] = find(static_cast<int>(t));
  return labels;
}

int exit_code_of(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e)) return 2;
  if (dynamic_cast<const NumericalError*>(&e)) return 3;
  if (dynamic_cast<const OutputError*>(&e)) return 5;
  return 4;
}

bool& failure_agreed() {
  static bool agreed = false;
  return agreed;
}

void agree(Transport& transport, std::exception_ptr failure) {
  int code = 0;
  std::string message;
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const std::exception& e) {
      code = exit_code_of(e);
      message = e.what();
    } catch (...) {
      code = 4;
      message = "unknown error";
    }
  }
  std::vector<char> mine(sizeof(int));
  std::memcpy(mine.data(), &code, sizeof(int));
  mine.insert(mine.end(), message.begin(), message.end());
  const auto all = transport.gather(mine);
  Bytes first(sizeof(int), 0);
  for (const auto& b : all) {
    int c = 0;
    std::memcpy(&c, b.data(), sizeof(int));
    if (c != 0) {
      first = b;
      break;
    }
  }
  const Bytes agreed = transport.broadcast(first);
  std::memcpy(&code, agreed.data(), sizeof(int));
  if (code == 0) return;
  message.assign(agreed.begin() + sizeof(int), agreed.end());
  failure_agreed() = true;
  switch (code) {
    case 2: throw InputError(message);
    case 3: throw NumericalError(message);
    case 5: throw OutputError(message);
    default: throw DeviceError(message);
  }
}

}  // namespace fdem
