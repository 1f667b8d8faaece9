// Running a case end to end: case → mesh → model → device → steps → Exodus + history
// (the driver: engine/run/run.cpp; ARCHITECTURE.md, "The run").
#pragma once
#include <csignal>
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/parallel/partition.hpp"
#include "engine/model/prepared_case.hpp"
#include "engine/run/prepare_case.hpp"
#include "engine/parallel/transport.hpp"

namespace fdem {

struct RunSummary {
  long steps = 0;
  double simulated_time = 0;
  double wall_seconds = 0;
  double ns_per_element_step = 0;
  double final_kinetic_energy = 0;
  double final_energy_error = 0;  // energy_error of the last history row
  double worst_energy_error = 0;  // largest |energy_error| of any row
  double final_unbalanced_ratio = 0;
  int frames = 0;
  long first_step = 0;       // the step the run started from (the checkpoint's, on restart)
  bool interrupted = false;  // stopped by a signal or --max-wall (a checkpoint was written)
  std::string stop_reason;   // "SIGTERM", "--max-wall", ...
  std::string checkpoint;    // the last checkpoint written
  double checkpoint_seconds = 0;  // wall time the last checkpoint took (device read, file, sync)
  size_t breaks = 0, events = 0;  // CE4s broken so far and the events they form (events file)
  // Contact classifications that visited only the couples no bond carries (ContactForces::
  // lean_classifications; this process's, since the run or the restart began). -1: none
  // could sleep (no contact, no CE4s, [[excavation]], or FDEM_CONTACT_SLEEPERS=0).
  long lean_classifications = -1;
};

struct RunOptions {
  std::string restart;  // checkpoint to continue from; empty: start at t = 0
  double max_wall = 0;  // [s] wall time after which the run stops cleanly; 0: no limit
  // Set (to the signal number) by a signal handler: the run stops cleanly after the step.
  const volatile std::sig_atomic_t* stop = nullptr;
  std::ostream* info = nullptr;  // where "resumed from ..." goes (else `log`)
  // A split run: this process is one of transport->size() > 1 ranks (mpirun; every rank
  // calls run_case with the same case), partitioned by `partition`. Rank 0 writes the files.
  Transport* transport = nullptr;
  PartitionMethod partition = PartitionMethod::Bisection;
  // A split run with contact: how far [m] a node may move from its start (its contact
  // ghosts; SplitRun). 0: default_contact_travel.
  double contact_travel = 0;
};

// Runs the prepared case on `cl`. Progress goes to `log` (a live status line when
// `status_line`, else periodic lines). Throws NumericalError after writing the last
// good frame when a NaN or an inverted element appears; OutputError when writing fails.
// With options.restart it continues from that checkpoint (InputError when the checkpoint
// does not fit the case: another mesh, precision or setting other than time.end and
// output.*), keeping the frames and rows written up to its time (InputError when the
// earlier files do not hold what the checkpoint lists: io/output_resume.hpp). The files
// are written as PATH.partial until the first frame or checkpoint; a run that fails before
// leaves an earlier run's files as they were. Checkpoints are written
// every output.checkpoint_every, at the end, and when stopped (options.stop, max_wall).
RunSummary run_case(const PreparedCase& prepared, ClContext& cl, std::ostream& log, bool status_line,
                    const RunOptions& options = {});

}  // namespace fdem
