// The break catalogue and its seismic events in one CF-style netCDF file, OUT/NAME_events.nc
// (docs/case-format.md, "Outputs"). Classic 64-bit-offset format like the other outputs:
// while the run goes, each batch of breaks is appended along the unlimited dimension
// `break` and synced (crash-safe); when the run ends, finish() writes the whole file again
// with the events (dimension `event`) beside a temporary name and renames it into place.
#pragma once
#include <string>
#include <vector>

#include "io/netcdf_file.hpp"

namespace fdem::io {

// One CE4 that broke (cl_kernels/cohesive_forces.cl records it at the step it breaks).
struct BreakRecord {
  double time = 0;    // [s] time of the step it broke in
  double x = 0, y = 0;  // [m] midpoint of its four nodes at that step
  double length = 0;  // [m] initial length h
  double energy = 0;  // [J] fracture energy it dissipated up to and including that step
  int mode = 0;       // 1 mode I, 2 mode II, 3 mixed
  long ce4 = -1;      // 0-based CE4 index (element ce4 + 1 of the Exodus cohesive block)
  long tri_a = -1, tri_b = -1;  // 0-based triangles (element + 1 of the Exodus file's TRI3 blocks)
  int joint = -1;     // the [[joint]] it lies on, 0-based (joint[joint]); -1: not on a joint
  int grain_boundary = -1;  // [grains]: 1 on a grain boundary, 0 inside a grain, -1 not between two grains
};

// Breaks grouped by proximity in space and time (engine/outputs/fracture_events.hpp).
struct EventRecord {
  double start = 0, end = 0;  // [s] first and last break
  double x = 0, y = 0;        // [m] mean of the breaks' midpoints
  long breaks = 0;
  double energy = 0;     // [J] sum of the breaks' break_energy
  double magnitude = 0;  // ⅔ (log10 energy − 4.8); NaN when energy <= 0
};

// The grouping rule's parameters, written as global attributes.
struct EventRule {
  double distance = 0;  // [m]
  double window = 0;    // [s]
};

class EventsWriter {
 public:
  // Creates (overwrites) `path` with the catalogue's variables and no records.
  // `grains`: the catalogue has break_grain_boundary ([grains] cases only).
  EventsWriter(const std::string& path, const std::string& title, bool grains = false);
  EventsWriter(const EventsWriter&) = delete;
  EventsWriter& operator=(const EventsWriter&) = delete;

  // Appends records (in the order given) and syncs.
  void append(const std::vector<BreakRecord>& records);
  // Closes the file and replaces it by one holding `all` (the whole catalogue) and
  // `events` (written to path + ".tmp", closed, then renamed over path). With no events
  // the file has no `event` dimension (classic netCDF has one unlimited dimension, and a
  // fixed one cannot be empty) and its global attribute `event_count` is 0.
  void finish(const std::vector<BreakRecord>& all, const std::vector<EventRecord>& events, const EventRule& rule);
  size_t breaks_written() const { return written_; }
  // The open file was renamed to `path` (a resumed run puts it in place): finish() writes
  // beside and over the new name.
  void moved_to(const std::string& path) { path_ = path, file_.moved_to(path); }
  const std::string& path() const { return path_; }
  void close() { file_.close(); }

 private:
  std::string path_, title_;
  bool grains_ = false;
  NetcdfFile file_;
  size_t written_ = 0;
};

// The records of events file `path` with break_time <= t_max (for a restart that does not
// carry them otherwise). OutputError when it cannot be read.
std::vector<BreakRecord> read_break_records(const std::string& path, double t_max);

}  // namespace fdem::io
