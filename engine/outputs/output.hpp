// An output of a run (ARCHITECTURE.md, "The run"): what it reads (needs), when it writes
// (a Trigger), and how it writes a Snapshot. Outputs never read the device and never
// know about ranks: the Domain reads, the OutputSet opens files only where it writes them.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/outputs/snapshot.hpp"
#include "io/output_resume.hpp"

namespace fdem {

// When an output writes, as a function of the step (and of its time, for a period in
// seconds), in the spirit of HOOMD-blue's Trigger.
class Trigger {
 public:
  static Trigger never() { return Trigger(Kind::Never); }
  // At the listed steps (sorted).
  static Trigger at_steps(std::vector<long> steps);
  // Every n steps after step 0, and at step `last`.
  static Trigger every_steps(long n, long last);
  // Each time the time passes a multiple of `period` [s] after `start` [s] (within
  // 1e-6 Δt); passed() moves on to the next multiple.
  static Trigger every_seconds(double period, double dt, double start);
  // Whenever any of `triggers` is due.
  static Trigger any_of(std::vector<const Trigger*> triggers);

  bool due(long step, double time) const;
  // Whether a longer run continuing this one writes a record at `step` too (the records a
  // restart copies over): the schedule without `last`.
  bool on_schedule(long step) const;
  // After a write at a due step (a period in seconds moves on).
  void passed(double time);

 private:
  enum class Kind { Never, Steps, Every, Seconds, AnyOf };
  explicit Trigger(Kind kind) : kind_(kind) {}
  Kind kind_;
  std::vector<long> steps_;
  long every_ = 1, last_ = -1;
  double period_ = 0, dt_ = 0, next_ = 0;
  std::vector<const Trigger*> any_;
};

// What a run's outputs add up to, for its summary.
struct OutputTotals {
  int frames = 0;
  std::vector<double> last_row;  // the history's last row
  int kinetic_column = -1, unbalanced_column = -1;
  size_t breaks = 0, events = 0;
  double checkpoint_seconds = 0;  // the last checkpoint's state read and file
};

class Output {
 public:
  // What the OutputSet does around a write: a record is kept when the run fails at its
  // step (history rows, breaks); a frame and a checkpoint are written after the rows
  // are synced and are states a failure may fall back to; a checkpoint puts the files in
  // place before it is written, a frame after.
  enum class Role { Record, Frame, Checkpoint };

  Output(std::string path, Trigger trigger) : path_(std::move(path)), trigger_(std::move(trigger)) {}
  virtual ~Output() = default;
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;

  virtual Role role() const = 0;
  virtual Needs needs() const = 0;
  bool due(long step, double time) const { return trigger_.due(step, time); }
  Trigger& trigger() { return trigger_; }
  // The file's final path; it is written as path() + ".partial" until placed.
  const std::string& path() const { return path_; }

  // Opens the file at `partial` (only where the domain writes files).
  virtual void open(const std::string& partial, const Snapshot& setup) = 0;
  virtual void write(const Snapshot& snap) = 0;
  // A restart: copies the records of the earlier file at path() up to the checkpoint
  // (io/output_resume.hpp); false when a stop ended the copy.
  virtual bool resume(const io::ResumeCopy&) { return true; }
  // The checkpoint's attribute listing this file's records (empty: none).
  virtual const char* digest_key() const { return ""; }
  virtual std::vector<std::uint64_t> digests() const { return {}; }
  virtual void moved_to(const std::string& path) = 0;
  virtual void sync() {}
  // The run's end (closes the file): `last` holds the breaks read last.
  virtual void finish(const Snapshot& last) = 0;
  virtual void add_totals(OutputTotals&) const {}

 private:
  std::string path_;
  Trigger trigger_;
};

}  // namespace fdem
