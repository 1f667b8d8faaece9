// The energy account of a run: every term of the balance at one time, and the error of
// the balance. docs/case-format.md defines each term by its formula; the kernels that
// compute them say how (cl_kernels/integrate.cl, triangle_forces.cl, boundary_loads.cl,
// cohesive_forces.cl, contact_forces.cl).
#pragma once
#include <array>
#include <cstddef>
#include <string>

#include <functional>
#include <vector>

#include "engine/cl_context.hpp"
#include "engine/memory_plan.hpp"
#include "engine/real.hpp"

namespace fdem {

struct EnergyTotals {
  // Stored [J], at the time of the row's energy evaluation.
  double kinetic = 0, strain = 0, cohesive_stored = 0, contact_stored = 0, gravity_potential = 0;
  // Dissipated [J], cumulative from t = 0.
  double viscous = 0, local_damping = 0, friction = 0, contact_damping = 0, fracture = 0, absorbed = 0;
  // Supplied [J], cumulative from t = 0.
  double boundary_work = 0, load_work = 0;
  // Round-off of the stored terms [J]: the strain energy and the contact potentials are
  // computed from absolute positions, each known to ε |x|, which bounds what the balance
  // can resolve (Solver::energy; docs/case-format.md, energy_error).
  double resolution = 0;

  double stored() const { return kinetic + strain + cohesive_stored + contact_stored + gravity_potential; }
  double dissipated() const { return viscous + local_damping + friction + contact_damping + fracture + absorbed; }
  double supplied() const { return boundary_work + load_work; }
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
// launch and a read of the blocks' sums); a split run's rank 0 applies the same rule to
// the values gathered in global order (ordered_sums); so one rank and any number of ranks
// give the same bits (ARCHITECTURE.md, "Scale-out").
enum class ItemKind { Node = 0, Triangle = 1, LoadedEdge = 2, Ce4 = 3 };
constexpr std::size_t kOrderedBlock = 256;

// Columns first … first + width − 1 of `count` rows of `stride` reals, summed by the rule.
std::vector<double> blocked_sums(const std::vector<real>& values, std::size_t count, int stride, int first, int width);

// The sums of columns [first, first + width) of a device array of `count` items of
// `stride` reals (real4: 4) of kind `kind`.
using ItemSums = std::function<std::vector<double>(ClContext& cl, const compute::buffer& values, std::size_t count,
                                                   int stride, int first, int width, ItemKind kind)>;
// ItemSums over all of one rank's items, on the host (for stages used alone: tests).
std::vector<double> all_items(ClContext& cl, const compute::buffer& values, std::size_t count, int stride, int first,
                              int width, ItemKind kind);

class Transport;
// One rank's items in the whole model, per kind: local → global index, whether this rank
// accounts for the item (owns it), and the global count.
struct ItemScope {
  Transport* transport = nullptr;
  std::array<std::vector<int>, 4> global;
  std::array<std::vector<char>, 4> owned;
  std::array<size_t, 4> global_count{};
};
// The sums of `values` (count × width reals, this rank's items) over every rank's owned
// items in global order, by the rule, on every rank (collective).
std::vector<double> ordered_sums(const std::vector<real>& values, int width, ItemKind kind, const ItemScope& scope);

// The device side of the rule for one rank (Solver): the kernel of
// cl_kernels/ordered_sum.cl and its array of block sums.
class OrderedSums {
 public:
  OrderedSums(ClContext& cl, std::size_t max_items);
  // The arrays it allocates for arrays of at most `max_items` items (4 columns at most).
  static MemoryPlan plan(std::size_t max_items);
  std::vector<double> sums(const compute::buffer& values, std::size_t count, int stride, int first, int width);

 private:
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
