// Time history in a CF-style netCDF file (classic 64-bit-offset, synced after each row).
#pragma once
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

  // Appends one row (values in the order of `variables`) and syncs.
  void append(double time, const std::vector<double>& values);
  int rows_written() const { return rows_; }
  const std::vector<std::string>& variable_names() const { return var_names_; }
  const std::string& path() const { return file_.path(); }
  void close() { file_.close(); }  // idempotent; the destructor closes and never throws

 private:
  NetcdfFile file_;
  int rows_ = 0;
  int time_var_ = -1;
  std::vector<int> var_ids_;
  std::vector<std::string> var_names_;
};

}  // namespace fdem::io
