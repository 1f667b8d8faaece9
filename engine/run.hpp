// Running a case end to end: case → mesh → model → device → steps → Exodus + history.
#pragma once
#include <csignal>
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/cl_context.hpp"
#include "engine/model.hpp"
#include "engine/partition.hpp"
#include "engine/transport.hpp"
#include "engine/probes.hpp"
#include "io/case_config.hpp"

namespace fdem {

// A case read, meshed and checked, ready to run.
struct PreparedCase {
  io::CaseConfig config;
  Model model;
  std::vector<std::string> notes;  // re-oriented triangles, dropped nodes, ...
  StableStep stable;               // stable Δt estimate
  double dt = 0;                   // the Δt the run uses
  long steps = 0;                  // number of steps
  std::string exodus_path, history_path;
  std::string fragments_path;  // OUT/NAME_fragments.nc, written when the model has CE4s
  std::string events_path;  // OUT/NAME_events.nc: break catalogue and events (models with CE4s only)
  std::vector<ProbeLocation> probes;  // [[probe]] points tied to their node and triangle
};

// Reads the case (with --set overrides), meshes a .geo if needed, builds the model and
// resolves Δt and the step count. Throws InputError for anything wrong, including a Δt
// above the stable estimate (unless mass scaling makes any Δt stable), an
// output.checkpoint_every shorter than Δt, and an output.dir that is the root of the file
// system or a system directory (/etc, /usr, ...).
PreparedCase prepare_case(const std::string& case_path, const std::vector<std::string>& overrides);

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

// OUT/NAME.ckpt: where a case's checkpoints go.
std::string checkpoint_path(const PreparedCase& prepared);

// Throws OutputError, with the message run_case would give, when the output folder can
// neither be written nor made, or one of the run's file names is taken by something other
// than a file. run_case checks it before anything is computed; `fdem check` too.
void check_output(const PreparedCase& prepared);

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
