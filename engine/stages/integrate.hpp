// Stage: central-difference integration with gravity, local damping and prescribed
// velocities (cl_kernels/integrate.cl), and the nodal part of the energy account.
#pragma once
#include <array>

#include "engine/device_arrays.hpp"
#include "engine/checkpoint.hpp"
#include "engine/energy.hpp"

namespace fdem {

class Integrate {
 public:
  // `prescribed`: some node has a prescribed velocity component (then the reactions'
  // work is accounted every step, as is the local damping's when local_damping > 0);
  // `account` false leaves both out (Solver's switch for measuring the account's cost).
  Integrate(ClContext& cl, DeviceArrays& arrays, std::array<double, 2> gravity,
            double local_damping, double dt, bool prescribed, bool account = true);
  // Advances every node from t to time_after = t + Δt. With energy_row, the step also
  // evaluates the kinetic energy and gravity potential at t (positions before the
  // update) for energy(). Never waits.
  void enqueue(double time_after, int step, bool energy_row = false);
  // From now on each step also writes the contact skin test of the next step into ring
  // slot slot_of(step + 1) of `monitor` (ContactSkin), against `position_at_build`.
  void add_skin_test(compute::buffer& position_at_build, compute::buffer& monitor, unsigned (*slot_of)(long));

  // Kinetic energy and gravity potential at the last energy row, and the local damping
  // dissipation and boundary (reaction) work from t = 0 up to it (waits).
  void add_energy(EnergyTotals& totals);

  // The cumulative energy sums, for checkpoints.
  void save_state(StateWriter& out) const {
    out.group_slots("integrate_work", group_work_, groups_, 2);
    if (account_work_) out.buffer<real>("integrate_node_work", node_work_, count_, 2);
  }
  void load_state(StateReader& in) {
    in.group_slots("integrate_work", group_work_, groups_, 2);
    if (account_work_) in.buffer<real>("integrate_node_work", node_work_, count_, 2);
  }

 private:
  ClContext& cl_;
  size_t count_, groups_;
  bool account_work_;
  compute::kernel kernel_;
  compute::buffer group_work_, group_row_;  // real2, real4 per work-group (the last energy row's sums)
  compute::buffer node_work_;  // real2 per node when accounted: (local damping work, reaction work) so far
  unsigned (*slot_of_)(long) = nullptr;
};

}  // namespace fdem
