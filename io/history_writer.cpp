#include "io/history_writer.hpp"

#include <netcdf.h>

#include <stdexcept>

namespace fdem::io {

HistoryWriter::HistoryWriter(const std::string& path, const std::string& title,
                             const std::vector<HistoryVariable>& variables)
    : file_("History output", path) {
  // A failure below leaves file_ to close the file: members are destroyed when a
  // constructor throws.
  file_.create();
  const int nc = file_.id();
  auto put_text_att = [&](int varid, const std::string& var, const char* name,
                          const std::string& value) {
    file_.check(nc_put_att_text(nc, varid, name, value.size(), value.c_str()),
                "writing attribute " + std::string(name) + " of " + var);
  };
  put_text_att(NC_GLOBAL, "the file", "title", title);
  put_text_att(NC_GLOBAL, "the file", "Conventions", "CF-1.8");
  put_text_att(NC_GLOBAL, "the file", "source", "fdem-cl");

  int dim_time = -1;
  file_.check(nc_def_dim(nc, "time", NC_UNLIMITED, &dim_time), "defining dimension time");
  file_.check(nc_def_var(nc, "time", NC_DOUBLE, 1, &dim_time, &time_var_),
              "defining variable time");
  put_text_att(time_var_, "time", "units", "s");
  put_text_att(time_var_, "time", "standard_name", "time");
  put_text_att(time_var_, "time", "long_name", "simulated time");
  put_text_att(time_var_, "time", "axis", "T");

  for (const HistoryVariable& v : variables) {
    int id = -1;
    // netCDF itself rejects bad or duplicate names (NC_EBADNAME, NC_ENAMEINUSE); the
    // message names the variable.
    file_.check(nc_def_var(nc, v.name.c_str(), NC_DOUBLE, 1, &dim_time, &id),
                "defining variable '" + v.name + "'");
    put_text_att(id, v.name, "units", v.units);
    put_text_att(id, v.name, "long_name", v.long_name);
    for (const auto& [att, values] : v.attributes)
      file_.check(nc_put_att_double(nc, id, att.c_str(), NC_DOUBLE, values.size(), values.data()),
                  "writing attribute " + att + " of " + v.name);
    var_ids_.push_back(id);
    var_names_.push_back(v.name);
  }
  file_.check(nc_enddef(nc), "finishing the header definition");
  file_.check(nc_sync(nc), "syncing the header");
}

void HistoryWriter::append(double time, const std::vector<double>& values) {
  if (!file_.is_open())
    throw std::logic_error("History output '" + path() + "': append after close");
  if (values.size() != var_ids_.size())
    throw std::invalid_argument("History output '" + path() + "', row " +
                                std::to_string(rows_) + ": " + std::to_string(values.size()) +
                                " values for " + std::to_string(var_ids_.size()) +
                                " variables");
  const int nc = file_.id();
  const size_t rec = static_cast<size_t>(rows_);
  auto check = [&](int status, int varid) {
    if (status == NC_NOERR) return;
    char name[NC_MAX_NAME + 1] = "?";
    nc_inq_varname(nc, varid, name);
    file_.fail(status, "row " + std::to_string(rows_) + ", variable " + name);
  };
  for (size_t k = 0; k < values.size(); ++k)
    check(nc_put_var1_double(nc, var_ids_[k], &rec, &values[k]), var_ids_[k]);
  check(nc_put_var1_double(nc, time_var_, &rec, &time), time_var_);
  ++rows_;
  digests_.push_back(row_digest(time, values));
  unsynced_ = true;
  if (sync_interval_ <= 0 ||
      std::chrono::duration<double>(std::chrono::steady_clock::now() - last_sync_).count() >= sync_interval_)
    sync();
}

void HistoryWriter::sync() {
  if (!unsynced_ || !file_.is_open()) return;
  file_.check(nc_sync(file_.id()), "row " + std::to_string(rows_ - 1) + ", sync");
  unsynced_ = false;
  last_sync_ = std::chrono::steady_clock::now();
}

std::uint64_t row_digest(double time, const std::vector<double>& values) {
  RecordDigest d;
  d.add(time);
  d.add(values.data(), values.size());
  return d.value();
}

}  // namespace fdem::io
