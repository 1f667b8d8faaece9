// The outputs of a run and their schedules (ARCHITECTURE.md, "The run"). Every rank holds
// the schedules (what is due, what it needs: the reads are collective); only where the
// domain writes files are the files open, so write() is an empty loop elsewhere.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/outputs/output.hpp"
#include "engine/model/prepared_case.hpp"
#include "engine/outputs/record_thread.hpp"

namespace fdem {

class OutputSet {
 public:
  // What is due at one step: the outputs in writing order and the union of their needs.
  struct Due {
    std::vector<Output*> outputs;
    Needs needs;
    bool any() const { return !outputs.empty(); }
  };

  // The outputs of case `p`, for a run that starts at `first_step`; their files are
  // written here when `writes_files` (Domain::writes_files).
  OutputSet(const PreparedCase& p, ClContext& cl, long first_step, bool writes_files);
  ~OutputSet();
  // What the files need when they are opened (setup in open()).
  Needs setup_needs() const;
  // Opens the files (where they are written) as PATH.partial (they are put in place at the first frame or
  // checkpoint: a run that fails before leaves an earlier run's files as they were).
  void open(const Snapshot& setup);
  // A restart: copies what the earlier files hold up to the checkpoint, as far as this
  // run's schedule has it (the row and frame a run writes at its own last step are not on
  // the schedule of a longer run, so a chain of runs writes the files one run would).
  // `earlier`: the digests of the records each file held, by checkpoint attribute. False
  // when `stopped` ended a copy.
  bool resume(const std::map<std::string, std::vector<std::uint64_t>>& earlier, const std::function<bool()>& stopped,
              std::ostream& info, long step, double time);

  Due due(long step, double time, bool stopping) const;
  // The outputs of a run's end: a checkpoint (and the breaks up to it).
  Due at_end() const;
  Needs frame_needs() const;
  // Writes what is due (where the files are) and moves the schedules on (everywhere).
  void write(const Due& due, const Snapshot& snap);
  // The same for the step loop: when only records are due (history rows, break events),
  // they are written by the record thread while the caller goes on stepping; their files
  // hold the rows once anything else is written, synced or closed, or totals() is asked.
  void write(const Due& due, Snapshot&& snap);
  // A failed step: only its records (history row, breaks).
  void write_records(const Due& due, const Snapshot& snap);
  // A frame of `snap` now (the last good state of a failed run).
  void write_frame(const Snapshot& snap);
  long last_frame_step() const { return last_frame_step_; }
  // Closes every file; `last` holds the breaks read last.
  void finish(const Snapshot& last);
  OutputTotals totals() const;
  const std::string& checkpoint_path() const;

 private:
  void place();
  void sync();
  const PreparedCase& p_;
  ClContext& cl_;  // its profile books each output's host time
  std::vector<std::unique_ptr<Output>> outputs_;  // in writing order
  Output* checkpoints_ = nullptr;
  Trigger breaks_at_stop_ = Trigger::never();
  const bool writes_files_;
  bool open_ = false, placed_ = false;
  long last_frame_step_ = -1;
  mutable RecordThread records_;  // destroyed first (declared last): no task outlives the files
};

}  // namespace fdem
