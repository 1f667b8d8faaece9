// The energy account of a run: every term of the balance at one time, and the error of
// the balance. docs/case-format.md defines each term by its formula; the kernels that
// compute them say how (cl_kernels/integrate.cl, triangle_forces.cl, boundary_loads.cl,
// cohesive_forces.cl, contact_forces.cl).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include <functional>
#include <utility>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/device/memory_plan.hpp"
#include "engine/model/real.hpp"
#include "engine/device/row_reads.hpp"
#include "engine/parallel/transport.hpp"

namespace fdem {

struct EnergyTotals {
  // Stored [J], at the time of the row's energy evaluation.
  double kinetic = 0, strain = 0, cohesive_stored = 0, contact_stored = 0, gravity_potential = 0;
  // Dissipated [J], cumulative from t = 0.
  double viscous = 0, local_damping = 0, friction = 0, contact_damping = 0, fracture = 0, absorbed = 0;
  // Strain energy carried out of the model by excavated triangles as their forces ramp
  // to zero [J], cumulative ([[excavation]]; docs/energy-notes.md, "Excavation").
  double excavated = 0;
  // Supplied [J], cumulative from t = 0.
  double boundary_work = 0, load_work = 0;
  // Round-off of the stored terms [J]: the strain energy and the contact potentials are
  // computed from absolute positions, each known to ε |x|, which bounds what the balance
  // can resolve (Solver::energy; docs/case-format.md, energy_error).
  double resolution = 0;
  // [fluid] (engine/stages/fluid_flow.*): the compressed fluid's energy (stored), the
  // viscous dissipation of the flow and the injection work (cumulative). The work of the
  // pressure on the faces passes from the fluid to the solid: not a term of the balance,
  // reported beside it; so are the fluid's volumes [m³] and the wellbore pressure [Pa].
  double fluid_stored = 0, fluid_viscous = 0, fluid_injection = 0;
  // Carter's leak-off: the leaked volume [m³] (beside the account) and the energy the
  // leaked fluid took out of the network [J] (dissipated: it left the model).
  double fluid_leak_off = 0, fluid_leaked_volume = 0;
  double fluid_face_work = 0, fluid_volume = 0, fluid_injected_volume = 0, wellbore_pressure = 0, crack_volume = 0;
  // [fluid.gas]: the blast hole's gas (FluidFlow::gas_hole) and ρ0, which turns the
  // volumes at reference density above into masses. The hole is the network's source:
  // outside the account, which books its wall work as load work and what it gives the
  // cracks as injection work.
  double hole_pressure = 0, hole_volume = 0, hole_gas_mass = 0, hole_gas_energy = 0, gas_density = 0;
  double fluid_substeps = 0;  // the flow's sub-steps in the last step (FluidFlow)

  double stored() const { return kinetic + strain + cohesive_stored + contact_stored + gravity_potential + fluid_stored; }
  double dissipated() const {
    return viscous + local_damping + friction + contact_damping + fracture + absorbed + excavated + fluid_viscous + fluid_leak_off;
  }
  double supplied() const { return boundary_work + load_work + fluid_injection; }
};

// Tracks a run's balance from its first evaluation (t = 0).
class EnergyBalance {
 public:
  void start(const EnergyTotals& initial);
  bool started() const { return started_; }
  // (stored + dissipated - supplied - initial stored) / the largest of |supplied|, initial
  // stored energy, the peak kinetic energy so far (updated by this call), |gravity
  // potential| (the work gravity has done, which LS-DYNA counts as supplied) and the account's
  // round-off bound (so that the first steps, when every energy is at the round-off of
  // the positions, do not count as errors; the bound is generous: in a coarse Brazilian
  // disc the contact potentials' actual noise was about 1/500 of it).
  double error(const EnergyTotals& now);
  // LS-DYNA's energy ratio: (stored + dissipated) / (initial stored + supplied); 1 balanced.
  double ratio(const EnergyTotals& now) const;
  // (initial stored energy, peak kinetic energy so far), for checkpoints.
  std::array<double, 2> state() const { return {initial_stored_, peak_kinetic_}; }
  void restore(const std::array<double, 2>& s) {
    started_ = true;
    initial_stored_ = s[0];
    peak_kinetic_ = s[1];
  }
  // The term (by history name) whose value changed most between two evaluations.
  static std::string largest_change(const EnergyTotals& before, const EnergyTotals& now);

 private:
  bool started_ = false;
  double initial_stored_ = 0, peak_kinetic_ = 0;
};

// Sums of per-item values that do not depend on how the model is split over ranks: each
// term of the account is a sum over items (nodes, triangles, loaded edges, CE4s) of the
// item's own value, added in the global item order by a fixed rule (blocked_sums: blocks
// of kOrderedBlock consecutive items, each summed left to right in `real`, the blocks'
// sums added in block order in double). One rank sums on the device (OrderedSums, one
// launch and a read of the blocks' sums); a split run applies the same rule on the hosts
// (SplitSums: each rank sums the blocks it owns entirely, rank 0 the blocks shared by
// several ranks, and adds all of them in block order); so one rank and any number of
// ranks give the same bits (ARCHITECTURE.md, "Scale-out").
enum class ItemKind { Node = 0, Triangle = 1, LoadedEdge = 2, Ce4 = 3 };
constexpr std::size_t kOrderedBlock = 256;

// Columns first … first + width − 1 of `count` rows of `stride` reals, summed by the rule.
std::vector<double> blocked_sums(const std::vector<real>& values, std::size_t count, int stride, int first, int width);

// Sums that may still be on their way from the device (a history row's reads, RowReads):
// calling the function gives them, waiting for the device if they have not landed.
using PendingSums = std::function<std::vector<double>()>;
inline PendingSums sums_now(std::vector<double> values) {
  return [values = std::move(values)] { return values; };
}
// A stage's share of the energy account, added to the totals once its reads have landed.
using EnergyPart = std::function<void(EnergyTotals&)>;

// The sums of columns [first, first + width) of a device array of `count` items of
// `stride` reals (real4: 4) of kind `kind`.
using ItemSums = std::function<PendingSums(ClContext& cl, const compute::buffer& values, std::size_t count,
                                           int stride, int first, int width, ItemKind kind)>;
// ItemSums over all of one rank's items, on the host (for stages used alone: tests).
PendingSums all_items(ClContext& cl, const compute::buffer& values, std::size_t count, int stride, int first,
                      int width, ItemKind kind);

// One rank's items in the whole model, per kind: local → global index, whether this rank
// accounts for the item (owns it), and the global count.
struct ItemScope {
  Transport* transport = nullptr;
  std::array<std::vector<int>, 4> global;
  std::array<std::vector<char>, 4> owned;
  std::array<size_t, 4> global_count{};
};

// One rank's owned items of one kind, cut by the rule's blocks: the blocks of which it
// owns every item (it sums them itself: a left-to-right sum in `real` gives the same bits
// on any host) and its items in the blocks that it shares with other ranks (their values
// go to rank 0, which sums those blocks). Every item has exactly one owner, so a rank
// finds its whole blocks alone, by counting its owned items per block.
struct BlockShare {
  std::vector<int64_t> whole;      // global block indices, ascending
  std::vector<int> whole_items;    // the local indices of the whole blocks' items, block after block, in global order
  std::vector<int64_t> shared;     // global indices of the owned items in the other blocks, ascending
  std::vector<int> shared_items;   // their local indices
  std::size_t global_count = 0;

  // From a rank's items (local → global index) and their owned flags.
  static BlockShare of(const std::vector<int>& global, const std::vector<char>& owned, std::size_t global_count);
  // What the rank sends of one row, into `out` (as `real`s): each whole block's sums of
  // columns [first, first + width) of `rows` (`stride` reals per local item), then each
  // shared item's values. Width 1 to 4.
  void message(const real* rows, int stride, int first, int width, Bytes& out) const;
};

// Rank 0's side: where every rank's message goes among the blocks (built once from every
// rank's BlockShare lists, in rank order; std::logic_error unless they cover every item
// exactly once).
class BlockMerge {
 public:
  BlockMerge() = default;
  BlockMerge(std::size_t global_count, const std::vector<std::vector<int64_t>>& whole,
             const std::vector<std::vector<int64_t>>& shared);
  // The rule's sums from every rank's message (BlockShare::message, in rank order).
  std::vector<double> sums(const std::vector<const Bytes*>& messages, int width) const;

 private:
  std::size_t global_count_ = 0;
  // Per block: the rank whose message holds its sums and their place among that rank's
  // whole blocks, or rank −1 (shared) and the place of its first item among the shared ones.
  struct Source {
    int rank;
    std::size_t index;
  };
  std::vector<Source> blocks_;
  // The shared items in global order, each by its owner: each rank's values come in
  // that order in its message, so a row reads every message once, front to back.
  std::vector<int> shared_rank_;
  std::vector<std::size_t> whole_count_, shared_count_;  // per rank
  // sums' loop over the blocks for W columns (`next`: each rank's next shared item).
  template <int W>
  void add_blocks(const std::vector<const Bytes*>& messages, std::vector<const char*>& next, double* total) const;
};

// A split run's ItemSums (Solver::energy) on one rank: BlockShare for each kind, and on
// rank 0 the BlockMerge of every rank's. The index sets are built once (ownership never
// changes), so a row is one read of the array, one pass over the owned items and one
// message per rank.
class SplitSums {
 public:
  // Collective: every rank's block lists travel to rank 0 once.
  explicit SplitSums(const ItemScope& scope);
  // ItemSums over every rank's owned items (`count` this rank's items), on every rank. Collective.
  std::vector<double> sums(ClContext& cl, const compute::buffer& values, std::size_t count, int stride, int first,
                           int width, ItemKind kind);

 private:
  Transport& transport_;
  std::array<BlockShare, 4> share_;
  std::array<BlockMerge, 4> merge_;  // rank 0
  // The buffers of a row, kept for the next (Transport::gather_into says why): the array
  // read (grown only), this rank's message per kind and, on rank 0, the others' messages.
  std::vector<real> rows_;
  std::array<Bytes, 4> message_;
  std::array<std::vector<Bytes>, 4> received_;
};

// A split run's contact stored energy (Solver::add_split_contact_energy). One rank sums
// its list's per-couple values per work-group by a tree (contact_stored_partials,
// group_sum4) and the groups in order in double. Only touching couples hold a value
// other than 0, and x + 0 = x, so the sum depends only on where the nonzero values sit
// in the whole sorted list: their global positions.

// For each of `queries` (ascending runs: a run restarts where a query is below the last
// one), how many of `sorted_keys` are smaller.
std::vector<uint64_t> count_below(const std::vector<cl_ulong>& sorted_keys, const std::vector<cl_ulong>& queries);

// The sum that contact_stored_partials and the host's addition of its slots give for a
// list that holds `nonzero` (global position in the list, value; ascending positions,
// values ≠ 0) and +0 elsewhere, in work-groups of `group` (a power of two).
double tree_group_sums(const std::vector<std::pair<uint64_t, real>>& nonzero, std::size_t group);

// The device side of the rule for one rank (Solver): the kernel of
// cl_kernels/ordered_sum.cl and its array of block sums.
class OrderedSums {
 public:
  OrderedSums(ClContext& cl, std::size_t max_items);
  // The arrays it allocates for arrays of at most `max_items` items (4 columns at most).
  static MemoryPlan plan(std::size_t max_items);
  std::vector<double> sums(const compute::buffer& values, std::size_t count, int stride, int first, int width);
  // The same sums, the blocks' sums read into `reads` without waiting.
  PendingSums queue(const compute::buffer& values, std::size_t count, int stride, int first, int width,
                    RowReads& reads);

 private:
  // Launches the kernel; returns the number of blocks.
  std::size_t launch(const compute::buffer& values, std::size_t count, int stride, int first, int width);
  ClContext& cl_;
  compute::kernel kernel_;
  compute::buffer partial_;
};

// Sums the per-work-group energy slots of a stage (`width` reals per group: real2 or
// real4) in group order, on the host, in double: the same order on every run.
std::array<double, 4> sum_group_slots(ClContext& cl, const compute::buffer& slots, std::size_t groups, int width);

// Number of work-groups ClContext::enqueue launches for n work-items.
inline std::size_t work_groups(const ClContext& cl, std::size_t n) { return (n + cl.group_size() - 1) / cl.group_size(); }

}  // namespace fdem
