#include "engine/energy.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "engine/device_arrays.hpp"
#include "engine/kernel_args.hpp"
#include "engine/transport.hpp"

namespace fdem {

void EnergyBalance::start(const EnergyTotals& initial) {
  started_ = true;
  initial_stored_ = initial.stored();
  peak_kinetic_ = std::max(0.0, initial.kinetic);
}

double EnergyBalance::error(const EnergyTotals& now) {
  peak_kinetic_ = std::max(peak_kinetic_, now.kinetic);
  // Gravity's work so far is minus its potential: LS-DYNA books it as external work.
  const double scale = std::max({std::fabs(now.supplied()), std::fabs(initial_stored_), peak_kinetic_,
                                 std::fabs(now.gravity_potential), now.resolution});
  const double residual = now.stored() + now.dissipated() - now.supplied() - initial_stored_;
  return scale > 0 ? residual / scale : 0.0;
}

double EnergyBalance::ratio(const EnergyTotals& now) const {
  const double in = initial_stored_ + now.supplied();
  return in != 0 ? (now.stored() + now.dissipated()) / in : 1.0;
}

std::string EnergyBalance::largest_change(const EnergyTotals& a, const EnergyTotals& b) {
  const std::pair<const char*, double> changes[] = {
      {"kinetic_energy", b.kinetic - a.kinetic},
      {"strain_energy", b.strain - a.strain},
      {"cohesive_stored_energy", b.cohesive_stored - a.cohesive_stored},
      {"contact_stored_energy", b.contact_stored - a.contact_stored},
      {"gravity_potential", b.gravity_potential - a.gravity_potential},
      {"viscous_dissipation", b.viscous - a.viscous},
      {"local_damping_dissipation", b.local_damping - a.local_damping},
      {"friction_dissipation", b.friction - a.friction},
      {"contact_damping_dissipation", b.contact_damping - a.contact_damping},
      {"fracture_dissipation", b.fracture - a.fracture},
      {"absorbed_energy", b.absorbed - a.absorbed},
      {"boundary_work", b.boundary_work - a.boundary_work},
      {"load_work", b.load_work - a.load_work}};
  const auto* best = &changes[0];
  for (const auto& c : changes)
    if (std::fabs(c.second) > std::fabs(best->second)) best = &c;
  return best->first;
}

std::array<double, 4> sum_group_slots(ClContext& cl, const compute::buffer& slots, std::size_t groups, int width) {
  std::array<double, 4> total = {0, 0, 0, 0};
  if (groups == 0) return total;
  const auto values = download<real>(cl, slots, groups * static_cast<std::size_t>(width));
  for (std::size_t g = 0; g < groups; ++g)
    for (int k = 0; k < width; ++k) total[k] += static_cast<double>(values[g * width + k]);
  return total;
}

}  // namespace fdem

namespace fdem {

std::vector<double> blocked_sums(const std::vector<real>& values, std::size_t count, int stride, int first, int width) {
  std::vector<double> total(static_cast<std::size_t>(width), 0.0);
  for (std::size_t begin = 0; begin < count; begin += kOrderedBlock) {
    const std::size_t end = std::min(count, begin + kOrderedBlock);
    for (int c = 0; c < width; ++c) {
      real s = 0;  // as the kernel: in `real`, left to right
      for (std::size_t i = begin; i < end; ++i) s += values[i * stride + first + c];
      total[c] += static_cast<double>(s);
    }
  }
  return total;
}

std::vector<double> all_items(ClContext& cl, const compute::buffer& values, std::size_t count, int stride, int first,
                              int width, ItemKind) {
  return blocked_sums(download<real>(cl, values, count * stride), count, stride, first, width);
}

std::vector<double> ordered_sums(const std::vector<real>& values, int width, ItemKind kind, const ItemScope& scope) {
  const std::size_t count = values.size() / static_cast<std::size_t>(width);
  const int k = static_cast<int>(kind);
  const auto& global = scope.global[k];
  const auto& owned = scope.owned[k];
  // (global index, row) of the owned items.
  std::vector<int64_t> ids;
  std::vector<real> rows;
  for (std::size_t i = 0; i < count; ++i)
    if (owned[i]) {
      ids.push_back(global[i]);
      rows.insert(rows.end(), values.begin() + i * width, values.begin() + (i + 1) * width);
    }
  Transport& t = *scope.transport;
  const auto all_ids = t.gather(to_bytes(ids));
  const auto all_rows = t.gather(to_bytes(rows));
  std::vector<double> sum(static_cast<std::size_t>(width), 0.0);
  if (t.rank() == 0) {
    const std::size_t n = scope.global_count[k];
    std::vector<real> ordered(n * width, real(0));
    std::size_t seen = 0;
    for (std::size_t r = 0; r < all_ids.size(); ++r) {
      const auto g = from_bytes<int64_t>(all_ids[r]);
      const auto v = from_bytes<real>(all_rows[r]);
      for (std::size_t i = 0; i < g.size(); ++i) std::copy(v.begin() + i * width, v.begin() + (i + 1) * width, ordered.begin() + g[i] * width);
      seen += g.size();
    }
    if (seen != n) throw std::logic_error("ordered_sums: the ranks own " + std::to_string(seen) + " of " + std::to_string(n) + " items");
    sum = blocked_sums(ordered, n, width, 0, width);
  }
  return from_bytes<double>(t.broadcast(to_bytes(sum)));
}

MemoryPlan OrderedSums::plan(std::size_t max_items) {
  const std::size_t blocks = std::max<std::size_t>(1, (max_items + kOrderedBlock - 1) / kOrderedBlock);
  return MemoryPlan().add("ordered_sums partial", 4 * blocks * sizeof(real));
}

OrderedSums::OrderedSums(ClContext& cl, std::size_t max_items) : cl_(cl) {
  kernel_ = compute::kernel(cl.build(kernel_source::ordered_sum, {{"ORDERED_BLOCK", std::to_string(kOrderedBlock)}}),
                            "ordered_block_sums");
  partial_ = plan(max_items).allocate(cl, "ordered_sums partial");
}

std::vector<double> OrderedSums::sums(const compute::buffer& values, std::size_t count, int stride, int first, int width) {
  std::vector<double> total(static_cast<std::size_t>(width), 0.0);
  if (count == 0) return total;
  const std::size_t blocks = (count + kOrderedBlock - 1) / kOrderedBlock;
  bind_args(kernel_)("n", static_cast<cl_uint>(count))("stride", static_cast<cl_uint>(stride))(
      "first", static_cast<cl_uint>(first))("width", static_cast<cl_uint>(width))("values", values)("partial", partial_)
      .done();
  cl_.enqueue(kernel_, blocks);
  const auto partial = download<real>(cl_, partial_, blocks * width);
  for (std::size_t b = 0; b < blocks; ++b)
    for (int c = 0; c < width; ++c) total[c] += static_cast<double>(partial[b * width + c]);
  return total;
}

}  // namespace fdem
