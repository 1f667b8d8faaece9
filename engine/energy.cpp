#include "engine/energy.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "engine/device_arrays.hpp"
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

std::vector<double> ordered_sums(const std::vector<double>& values, int width, ItemKind kind, const ItemScope* scope) {
  std::vector<double> sum(static_cast<size_t>(width), 0.0);
  const size_t count = values.size() / static_cast<size_t>(width);
  if (!scope || !scope->transport) {
    for (size_t i = 0; i < count; ++i)
      for (int k = 0; k < width; ++k) sum[k] += values[i * width + k];
    return sum;
  }
  const int kind_index = static_cast<int>(kind);
  const auto& global = scope->global[kind_index];
  const auto& owned = scope->owned[kind_index];
  // (global index, values) of the owned items, as doubles.
  std::vector<double> mine;
  for (size_t i = 0; i < count; ++i)
    if (owned[i]) {
      mine.push_back(static_cast<double>(global[i]));
      mine.insert(mine.end(), values.begin() + i * width, values.begin() + (i + 1) * width);
    }
  Transport& t = *scope->transport;
  const auto all = t.gather(to_bytes(mine));
  if (t.rank() == 0) {
    const size_t n = scope->global_count[kind_index];
    std::vector<double> ordered(n * width, 0.0);
    std::vector<char> seen(n, 0);
    for (const auto& b : all) {
      const auto v = from_bytes<double>(b);
      for (size_t at = 0; at + width < v.size() + 1; at += width + 1) {
        const size_t g = static_cast<size_t>(v[at]);
        seen[g] = 1;
        std::copy(v.begin() + at + 1, v.begin() + at + 1 + width, ordered.begin() + g * width);
      }
    }
    if (std::count(seen.begin(), seen.end(), 0) != 0)
      throw std::logic_error("ordered_sums: an item is owned by no rank");
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < width; ++k) sum[k] += ordered[i * width + k];
  }
  return from_bytes<double>(t.broadcast(to_bytes(sum)));
}

}  // namespace fdem
