// What stops a run that went wrong (ARCHITECTURE.md, "The run"): a non-finite node or an
// inverted triangle (the kernels' condition flags, read with every output and every
// kCheckStride steps), and an energy balance that does not close (output.energy_limit).
// The last-good-frame rule: a failed condition writes the last passed copy of the state
// as the last frame, an energy limit the state at that step (after its history row).
#pragma once
#include <ostream>

#include "engine/outputs/output_set.hpp"
#include "engine/run/domain.hpp"

namespace fdem {

class RunGuard {
 public:
  static constexpr long kCheckStride = 200;
  RunGuard(const PreparedCase& p, double worst_energy_error, std::ostream& log, bool status_line)
      : p_(p), worst_(worst_energy_error), log_(log), status_line_(status_line) {}
  // A step whose conditions are checked without any output due.
  bool check_due(long step) const { return step % kCheckStride == 0; }
  // Throws NumericalError when `snap` failed, after the last-good-frame rule (and, for
  // the energy limit, after writing the step's records); warns once when the energy
  // error passes 1 %. Fills snap.worst_energy_error. Collective (the frames' reads).
  void check(Snapshot& snap, Domain& domain, OutputSet& outputs, const OutputSet::Due& due);
  double worst_energy_error() const { return worst_; }
  double final_energy_error() const { return final_; }

 private:
  const PreparedCase& p_;
  double worst_ = 0, final_ = 0;
  bool warned_ = false;
  EnergyTotals last_energy_;
  std::ostream& log_;
  bool status_line_;
};

}  // namespace fdem
