#include "engine/energy.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "engine/device_arrays.hpp"

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
