// What one read of the run's state holds (ARCHITECTURE.md, "The run"): the whole model in
// global order, whatever the number of ranks, and only what the outputs due asked for.
#pragma once
#include <cstddef>
#include <vector>

#include "engine/energy/energy.hpp"
#include "engine/model/real.hpp"
#include "engine/solver.hpp"
#include "io/checkpoint_file.hpp"
#include "io/events_writer.hpp"

namespace fdem {

// One thing an output reads (a bit of Needs).
enum class Need : unsigned {
  Conditions = 1u << 0,      // the NaN and inversion flags (RunGuard); read first, the rest only when they pass
  Energy = 1u << 1,          // the energy account of the step (the step evaluates its stored energies)
  Positions = 1u << 2,
  Velocities = 1u << 3,
  Forces = 1u << 4,          // out-of-balance force of the last step
  Stress = 1u << 5,          // evaluated for the output (one triangle pass)
  ContactForces = 1u << 6,
  Ce4Flags = 1u << 7,        // broken, mode
  Ce4State = 1u << 8,        // damage, opening, slip
  FragmentLabels = 1u << 9,  // the pieces (needs Ce4Flags)
  ContactCounts = 1u << 10,  // touching couples, candidates, detections
  Probes = 1u << 11,         // [[probe]] values (evaluate the stress)
  Breaks = 1u << 12,         // the CE4 breaks since the last read
  Catalogue = 1u << 13,      // every break so far (a run's start)
  State = 1u << 14,          // the whole state a run continues from (checkpoints)
  Masses = 1u << 15,         // (lumped mass, inertia) per node
  GoodCopy = 1u << 16,       // not read: the output is a passed state a failure may fall back to (RunGuard)
  FluidSegments = 1u << 17,  // [fluid]: per CE4 the network's pressure and aperture (FluidFlow::segment_fields)
};

class Needs {
 public:
  Needs() = default;
  Needs(Need n) : bits_(static_cast<unsigned>(n)) {}  // NOLINT: a single need is a set
  bool has(Need n) const { return (bits_ & static_cast<unsigned>(n)) != 0; }
  bool any() const { return bits_ != 0; }
  Needs operator|(Needs o) const { return from(bits_ | o.bits_); }
  Needs& operator|=(Needs o) { bits_ |= o.bits_; return *this; }
  Needs without(Need n) const { return from(bits_ & ~static_cast<unsigned>(n)); }

 private:
  static Needs from(unsigned bits) { Needs n; n.bits_ = bits; return n; }
  unsigned bits_ = 0;
};
inline Needs operator|(Need a, Need b) { return Needs(a) | Needs(b); }

// One read of the state (Domain::read). The whole-model fields are filled where the
// domain writes files (the one process, rank 0 of a split run) and empty elsewhere;
// conditions, energy and the counts are the same on every rank.
struct Snapshot {
  long step = 0;
  double time = 0;
  Needs has;
  Conditions conditions;  // with Need::Conditions; when not ok() nothing after it was read
  EnergyTotals energy;    // Need::Energy: the account, its error and ratio, at energy_time
  double energy_error = 0, energy_ratio = 0, energy_time = 0;
  std::vector<real2> positions, velocities, forces, contact_forces;
  std::vector<real4> stress;
  std::vector<real> damage, opening, slip;
  std::vector<int> broken, mode, labels;
  std::vector<real> fluid_pressure, fluid_aperture;  // FluidSegments: per CE4 [Pa, m]; 0 on a closed segment
  size_t contact_touching = 0, contact_candidates = 0;
  long contact_rebuilds = 0;
  std::vector<double> probes;            // per probe (vx, vy, sxx, syy, sxy, ps1), in PointProbes' order
  std::vector<io::BreakRecord> breaks;   // Breaks or Catalogue: global CE4 indices, with their triangles
  io::CheckpointData state;              // State: the whole model's, as one rank writes it
  long inserted_ce4 = 0;                 // Ce4Flags: extrinsic CE4s inserted so far
  long broken_ce4 = 0;                   // State: CE4s broken so far
  double state_seconds = 0;              // State: the wall time its read took
  std::vector<real2> masses;             // Masses
  double worst_energy_error = 0;         // the largest |energy_error| so far (RunGuard::check fills it)
  bool passed() const { return conditions.ok(); }
};

}  // namespace fdem
