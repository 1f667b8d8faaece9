// Time history in a CF-style netCDF file (classic 64-bit-offset, synced after each row, or
// at most every sync_interval seconds of wall time when one is set).
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "io/netcdf_file.hpp"

namespace fdem::io {

struct HistoryVariable {
  std::string name;       // netCDF variable name, e.g. "kinetic_energy", "top_force_y"
  std::string units;      // CF units string, e.g. "J", "N", "m"
  std::string long_name;  // human-readable description
  // Extra numeric attributes (name, values), e.g. a probe's point: ("probe_point", {x, y}).
  std::vector<std::pair<std::string, std::vector<double>>> attributes = {};
};

class HistoryWriter {
 public:
  // Creates (overwrites) `path` with an unlimited `time` coordinate (units "s") and one
  // double variable per entry of `variables`. Throws fdem::OutputError naming the path.
  HistoryWriter(const std::string& path, const std::string& title,
                const std::vector<HistoryVariable>& variables);
  HistoryWriter(const HistoryWriter&) = delete;
  HistoryWriter& operator=(const HistoryWriter&) = delete;

  // Appends one row (values in the order of `variables`) and syncs: every row, or with a
  // sync interval when the last sync is that old (a killed run keeps every synced row).
  void append(double time, const std::vector<double>& values);
  // Rows a few steps apart made the sync (a header write and a flush, 20-40 µs) a large
  // part of a small model's step: with `seconds` > 0 a row syncs only when the last sync
  // is at least that old; sync() then makes every row so far safe (checkpoints, frames).
  void set_sync_interval(double seconds) { sync_interval_ = seconds; }
  void sync();
  int rows_written() const { return rows_; }
  // The digest of every row written (io::row_digest).
  const std::vector<std::uint64_t>& row_digests() const { return digests_; }
  const std::vector<std::string>& variable_names() const { return var_names_; }
  const std::string& path() const { return file_.path(); }
  void close() { file_.close(); }  // idempotent; the destructor closes and never throws
  void moved_to(const std::string& path) { file_.moved_to(path); }

 private:
  NetcdfFile file_;
  int rows_ = 0;
  std::vector<std::uint64_t> digests_;
  double sync_interval_ = 0;
  bool unsynced_ = false;
  std::chrono::steady_clock::time_point last_sync_ = std::chrono::steady_clock::now();
  int time_var_ = -1;
  std::vector<int> var_ids_;
  std::vector<std::string> var_names_;
};

// The digest of a history row: its time, then its values in the order of the variables.
std::uint64_t row_digest(double time, const std::vector<double>& values);

}  // namespace fdem::io
