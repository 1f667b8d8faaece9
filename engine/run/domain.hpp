// Where a run's model lives (ARCHITECTURE.md, "The run"): on one device (WholeDomain) or
// split over the ranks of `mpirun` (SplitDomain, engine/run/split_run.*). The Domain is the
// only type that knows which: the driver, the outputs and the guard call the same
// functions in the same order on every rank (each call that reads is collective in a
// split run), and one factory picks the domain, once.
#pragma once
#include <exception>
#include <functional>
#include <memory>
#include <string>

#include "engine/outputs/snapshot.hpp"
#include "engine/model/prepared_case.hpp"
#include "engine/solver.hpp"

namespace fdem {

class Transport;
enum class PartitionMethod;

// The break records with the two triangles of each record's CE4 filled in (both domains'
// break reads).
std::vector<io::BreakRecord> with_triangles(const Model& model, std::vector<io::BreakRecord> records);

// A stop asked for (a signal, --max-wall), as every rank agrees on it.
struct StopRequest {
  int signal = 0;
  bool out_of_time = false;
  bool any() const { return signal != 0 || out_of_time; }
};

class Domain {
 public:
  virtual ~Domain() = default;
  Solver& solver() { return *solver_; }
  // Whether the run's files are written here (the one process; rank 0 of a split run).
  virtual bool writes_files() const = 0;
  // After each step: the ghost exchange of a split run.
  virtual void after_step() = 0;
  // One read of the state, the whole model in global order (on the writing rank): what
  // `needs` asks for. With Need::Conditions those are read first, and nothing else when
  // they fail. Collective.
  virtual Snapshot read(Needs needs) = 0;
  // Every rank passes what it failed with (null: nothing); every rank then throws the
  // first failure, or none does. Collective.
  virtual void agree(std::exception_ptr failure) = 0;
  // A stop as every rank sees it; `talk`: the ranks exchange it at this step (else a
  // split run goes on, and they agree at the next step that talks). Collective.
  virtual StopRequest agree_stop(StopRequest mine, bool talk) = 0;
  // Whether a stop may end a long copy at once (no rank to agree with).
  virtual bool stops_alone() const = 0;
  // Continues from a checkpoint of the whole model (each rank takes its share).
  virtual void load(const io::CheckpointData& whole, const std::string& path) = 0;

  // The copy of a passed state a failure falls back to (RunGuard).
  void keep_good_copy() { solver_->save_checkpoint(); }
  bool has_good_copy() const { return solver_->has_checkpoint(); }
  void restore_good_copy() { solver_->restore_checkpoint(); }
  // Gives back the arrays an output step read (the stress) until the next one.
  void release_output() { solver_->release_output(); }

 protected:
  std::unique_ptr<Solver> solver_;
};

// The domain of case `p` on `cl`: split when `transport` has more than one rank. `setup`
// runs first (the output folder's checks); its failure, and any in building the domain,
// is agreed on by every rank.
std::unique_ptr<Domain> make_domain(const PreparedCase& p, ClContext& cl, Transport* transport,
                                    PartitionMethod partition, double contact_travel, const std::function<void()>& setup);

}  // namespace fdem
