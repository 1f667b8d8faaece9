// The run driver (ARCHITECTURE.md, "The run"): the same on every rank. Each step asks the
// outputs what they will read, steps, and when anything is due reads one Snapshot from
// the Domain, lets the RunGuard check it and the outputs write it.
#include "engine/run/run.hpp"

#include <chrono>
#include <csignal>
#include <ostream>

#include "base/format.hpp"
#include "engine/outputs/output_set.hpp"
#include "engine/run/domain.hpp"
#include "engine/run/progress.hpp"
#include "engine/run/restart.hpp"
#include "engine/run/run_guard.hpp"

namespace fdem {

namespace {

std::string signal_name(int signal) {
  return signal == SIGTERM ? "SIGTERM" : signal == SIGINT ? "SIGINT" : signal == SIGUSR1 ? "SIGUSR1" : "a signal";
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

RunSummary run_case(const PreparedCase& p, ClContext& cl, std::ostream& log, bool status_line,
                    const RunOptions& options) {
  std::ostream& info = options.info ? *options.info : log;
  // Before anything is computed: the folder and the file names the run will write.
  const auto domain = make_domain(p, cl, options.transport, options.partition, options.contact_travel, [&] {
    check_output(p);
    make_output_dir(p.config.output.dir);
  });
  Solver& solver = domain->solver();
  RunSummary summary;
  const bool resumed = !options.restart.empty();
  Restart restart;
  if (resumed) {
    restart = load_restart(*domain, p, options.restart);
    info << "resumed from " << options.restart << " at step " << solver.steps_done() << ", t = "
         << format_number(solver.time(), 10) << " s\n" << std::flush;
  }
  const long first = solver.steps_done();
  summary.first_step = first;
  RunGuard guard(p, restart.worst_energy_error, log, status_line);

  // The files (as PATH.partial until the first frame or checkpoint), where the domain
  // writes them; a resumed run first copies what the earlier files hold up to its step.
  OutputSet outputs(p, cl, first, domain->writes_files());
  const Snapshot setup = domain->read(outputs.setup_needs());
  std::exception_ptr failure;
  bool copied = true;
  try {
    outputs.open(setup);
    // A signal while a long copy goes stops with the checkpoint as it is (one process;
    // the ranks of a split run stop together in the steps that follow).
    auto stopped = [&] { return domain->stops_alone() && options.stop && *options.stop != 0; };
    if (resumed) copied = outputs.resume(restart.digests, stopped, info, first, solver.time());
  } catch (...) {
    failure = std::current_exception();
  }
  domain->agree(failure);
  if (!copied) {  // the earlier files and the checkpoint are as they were: the same command resumes
    summary.interrupted = true;
    summary.stop_reason = signal_name(static_cast<int>(*options.stop));
    summary.checkpoint = options.restart;
    summary.simulated_time = solver.time();
    return summary;
  }
  if (!resumed) {  // the initial frame
    const OutputSet::Due due = outputs.due(first, solver.time(), false);
    if (due.any()) outputs.write(due, domain->read(due.needs));
  }
  domain->keep_good_copy();
  domain->release_output();

  const auto start = std::chrono::steady_clock::now();
  Progress progress(log, status_line, first, p.steps);
  for (long s = first + 1; s <= p.steps; ++s) {
    OutputSet::Due due = outputs.due(s, s * p.dt, false);
    solver.step(due.needs.has(Need::Energy));
    domain->after_step();
    const bool check = guard.check_due(s);
    const StopRequest mine{options.stop ? static_cast<int>(*options.stop) : 0,
                           options.max_wall > 0 && seconds_since(start) > options.max_wall};
    const StopRequest stop = domain->agree_stop(mine, due.any() || check);
    const bool stopping = stop.any() && s < p.steps;
    if (stopping) due = outputs.due(s, s * p.dt, true);
    if (due.any() || check || stopping) {
      const auto began = std::chrono::steady_clock::now();
      Snapshot snap = domain->read(due.needs | Need::Conditions);
      if (cl.profiling()) cl.add_host_time("output step: snapshot read (host wall, incl. the wait for the queue)", seconds_since(began));
      guard.check(snap, *domain, outputs, due);
      outputs.write(due, std::move(snap));  // records: on the record thread, while the next steps run
      // The copy a failure rolls back to: at the checks and at frames and checkpoints, not
      // at every history row (a row every few steps would read the state back as often).
      if (check || due.needs.has(Need::GoodCopy)) domain->keep_good_copy();
      domain->release_output();  // the output arrays of this step (stress) until the next output
      cl.collect_profile();
      if (stopping) {
        summary.interrupted = true;
        summary.stop_reason = stop.signal ? signal_name(stop.signal) : "--max-wall " + format_number(options.max_wall) + " s";
        break;
      }
    }
    progress.report(s, solver.time(), seconds_since(start));
  }
  cl.finish();
  const double wall = seconds_since(start);
  if (status_line) log << "\n";

  // Every run ends with a checkpoint, finished or stopped, and the catalogue's events.
  const OutputSet::Due end = outputs.at_end();
  Snapshot last = domain->read(end.needs);
  guard.check(last, *domain, outputs, end);
  outputs.write(end, last);
  outputs.finish(domain->read(Need::Breaks));

  const OutputTotals totals = outputs.totals();
  summary.steps = solver.steps_done() - first;
  summary.simulated_time = solver.time();
  summary.wall_seconds = wall;
  summary.ns_per_element_step =
      1e9 * wall / (double(std::max(1L, summary.steps)) * std::max<size_t>(1, p.model.num_triangles()));
  summary.frames = totals.frames;
  if (!totals.last_row.empty()) {
    summary.final_kinetic_energy = totals.last_row[totals.kinetic_column];
    summary.final_unbalanced_ratio = totals.last_row[totals.unbalanced_column];
  }
  summary.worst_energy_error = guard.worst_energy_error();
  summary.final_energy_error = guard.final_energy_error();
  summary.checkpoint = outputs.checkpoint_path();
  summary.checkpoint_seconds = totals.checkpoint_seconds;
  summary.breaks = totals.breaks, summary.events = totals.events;
  if (solver.contact() && solver.contact()->sleepers())
    summary.lean_classifications = solver.contact()->lean_classifications();
  return summary;
}

}  // namespace fdem
