// One model run over several ranks (`mpirun -np N fdem run`; ARCHITECTURE.md,
// "Scale-out"): each rank reads the same case, partitions the model the same way
// (engine/parallel/partition.*), builds its local model (own elements and nodes plus ghosts) and a
// Solver on its own device, and exchanges its ghost nodes' positions and velocities
// after every step (engine/parallel/halo.*). Sums of the energy account are taken per item in
// global order by one rule (SplitSums), output is gathered to rank 0 in global order,
// and rank 0 writes the one set of files, byte for byte as one rank writes them.
#pragma once
#include <exception>
#include <memory>
#include <vector>

#include "engine/energy/energy.hpp"
#include "engine/parallel/halo.hpp"
#include "engine/parallel/partition.hpp"
#include "engine/model/probes.hpp"
#include "engine/solver.hpp"
#include "engine/parallel/transport.hpp"
#include "io/checkpoint_file.hpp"
#include "io/events_writer.hpp"

namespace fdem {

struct PreparedCase;

// How many of the whole model's extrinsic CE4s `inserted` (its flags, per CE4 of `global`)
// marks inserted: what one rank's insertion counter holds.
size_t count_inserted(const Model& global, const std::vector<cl_int>& inserted);

class SplitRun {
 public:
  // Partitions `global` (the whole model, the same on every rank) and builds this rank's
  // share. With contact, every rank holds the triangles within contact_ghost_reach(global, travel) of its own, and
  // the run stops (InputError, on every rank at once) at a detection where some node has
  // moved more than `travel` [m] from its start (0: default_contact_travel).
  SplitRun(const Model& global, Transport& transport, PartitionMethod method, double travel = 0);

  Transport& transport() { return transport_; }
  bool root() const { return transport_.rank() == 0; }
  const Model& local_model() const { return local_.model; }
  const LocalModel& local() const { return local_; }
  const ItemScope& scope() const { return scope_; }
  // Builds the exchange on the solver's arrays and gives the solver the item scope (and,
  // with contact, the contact force exchange, the detection guard and the skin's reduction).
  void attach(ClContext& cl, Solver& solver);
  double contact_travel() const { return travel_; }
  // The ghost exchange after a step; none with extrinsic CE4s, whose step exchanges the
  // ghosts itself after the tie, and nothing moves a node after that (attach).
  void exchange() {
    if (!exchanged_in_step_) halo_->exchange();
  }

  // The owned items' values of every rank, on rank 0 in global order (empty elsewhere).
  // Collective.
  template <class T>
  std::vector<T> gather(ItemKind kind, const std::vector<T>& values) {
    const int k = static_cast<int>(kind);
    std::vector<int> ids;
    std::vector<T> mine;
    for (size_t i = 0; i < values.size(); ++i)
      if (scope_.owned[k][i]) ids.push_back(scope_.global[k][i]), mine.push_back(values[i]);
    const auto all_ids = transport_.gather(to_bytes(ids));
    const auto all_values = transport_.gather(to_bytes(mine));
    std::vector<T> out;
    if (!root()) return out;
    out.resize(scope_.global_count[k]);
    for (size_t r = 0; r < all_ids.size(); ++r) {
      const auto g = from_bytes<int>(all_ids[r]);
      const auto v = from_bytes<T>(all_values[r]);
      for (size_t i = 0; i < g.size(); ++i) out[g[i]] = v[i];
    }
    return out;
  }

  // The first offenders of every rank, in global indices, smallest over the ranks (what
  // one rank's atomic minima give). Collective.
  Conditions conditions(Solver& solver);
  // The [[probe]] values of the current state (PointProbes::variables' order, as one rank reads them) on
  // rank 0, empty elsewhere: each rank evaluates its stress, the owners of a probe's node
  // and triangle send their values. Collective.
  std::vector<double> probe_values(Solver& solver, const std::vector<ProbeLocation>& probes);
  // Checkpoints at any rank count: the arrays of the Solver's state (Solver::save_state)
  // are per node, triangle, loaded edge or CE4 (checkpoint_items), so rank 0 assembles
  // the whole model's from every rank's owned items (gather_state; collective), in the
  // layout one rank writes, and each rank takes its own and its ghosts' items from such a
  // file (local_state). The break log is the whole run's `catalogue` (global CE4s).
  io::CheckpointData gather_state(const io::CheckpointData& local, const std::vector<io::BreakRecord>& catalogue);
  io::CheckpointData local_state(const io::CheckpointData& global) const;
  // Every rank's owned CE4s' records of its catalogue (global CE4 indices), sorted, on
  // rank 0. Collective.
  std::vector<io::BreakRecord> catalogue(CohesiveForces& ce4);
  // The breaks of owned CE4s drained on every rank since the last call, with global CE4
  // indices, sorted by (time, CE4) on rank 0 (empty elsewhere). Collective.
  std::vector<io::BreakRecord> drain_breaks(CohesiveForces& ce4);

 private:
  Transport& transport_;
  const Model& global_;
  Partition partition_;
  LocalModel local_;
  ItemScope scope_;
  std::unique_ptr<HaloExchange> halo_;
  double travel_ = 0;
  bool exchanged_in_step_ = false;  // extrinsic CE4s: the step's own exchanges (attach)
  // The contact arrays of a checkpoint that are not per item (engine/run/split_run.cpp).
  void gather_contact(io::CheckpointData& global, const io::CheckpointData& local);
  void local_contact(io::CheckpointData& local) const;
  // At a detection (contact): the largest move of an owned node from its start, over all
  // ranks; stops every rank when it exceeds travel_. Collective.
  void check_travel(Solver& solver);
};

// Contact in a split run: how far a node may travel from its start before the contact
// ghosts no longer cover every couple (default: two mean edges of the mesh, or ten contact
// skins if that is more), and the reach of the ghosts around a rank's triangles'
// reference boxes that this allows: the skin (two boxes grown by skin/2 each) plus twice
// the travel (both triangles may move), with a little room for rounding.
double default_contact_travel(const Model& model);
double contact_ghost_reach(const Model& model, double travel);

// The pieces of the body from the CE4s' broken flags, on the host: per triangle the
// smallest triangle index of its piece (triangles joined through shared nodes and intact
// CE4s), as FragmentLabels computes them on the device.
std::vector<int> host_fragment_labels(const Model& model, const std::vector<int>& broken);

// The exit code fdem gives for an error (InputError 2, NumericalError 3, DeviceError 4,
// OutputError 5; anything else 4).
int exit_code_of(const std::exception& e);

// Start-up agreement: every rank passes what it failed with (null: nothing). When some
// rank failed, every rank throws the error of the lowest such rank (same type, same
// message), so all end with one message and one exit code. Collective.
void agree(Transport& transport, std::exception_ptr failure);

// Set before an error is thrown on every rank at once (agree, a failed condition check,
// the energy limit): main then ends normally with the exit code; any other error in a
// split run ends every rank through Transport::abort.
bool& failure_agreed();

}  // namespace fdem
