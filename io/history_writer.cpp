#include "io/history_writer.hpp"

#include <netcdf.h>

#include <filesystem>
#include <stdexcept>
#include <utility>

#include "base/errors.hpp"

namespace fdem::io {

namespace {

[[noreturn]] void throw_output_error(const std::string& path, int status,
                                     const std::string& what) {
  throw OutputError("History output '" + path + "': " + nc_strerror(status) + " (" + what +
                    ")");
}

// nc_create unlinks the path when creation fails (seen with netCDF-C 4.9.0), so an
// existing path that is not a regular file (a device such as /dev/null, a FIFO) is
// refused before netCDF touches it.
void refuse_non_regular(const std::string& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    throw OutputError("History output '" + path + "': exists and is not a regular file");
}

}  // namespace

HistoryWriter::HistoryWriter(const std::string& path, const std::string& title,
                             const std::vector<HistoryVariable>& variables)
    : path_(path) {
  refuse_non_regular(path_);

  // The constructor's own failures must release the handle: no destructor runs then.
  try {
    auto check = [&](int status, const std::string& what) {
      if (status != NC_NOERR) throw_output_error(path_, status, what);
    };
    auto put_text_att = [&](int varid, const std::string& var, const char* name,
                            const std::string& value) {
      check(nc_put_att_text(ncid_, varid, name, value.size(), value.c_str()),
            "writing attribute " + std::string(name) + " of " + var);
    };
    check(nc_create(path_.c_str(), NC_CLOBBER | NC_64BIT_OFFSET, &ncid_), "creating the file");
    // Each row writes every variable, so pre-filling records is wasted I/O.
    int old_fill = 0;
    check(nc_set_fill(ncid_, NC_NOFILL, &old_fill), "setting fill mode");

    put_text_att(NC_GLOBAL, "the file", "title", title);
    put_text_att(NC_GLOBAL, "the file", "Conventions", "CF-1.8");
    put_text_att(NC_GLOBAL, "the file", "source", "fdem-cl");

    int dim_time = -1;
    check(nc_def_dim(ncid_, "time", NC_UNLIMITED, &dim_time), "defining dimension time");
    check(nc_def_var(ncid_, "time", NC_DOUBLE, 1, &dim_time, &time_var_),
          "defining variable time");
    put_text_att(time_var_, "time", "units", "s");
    put_text_att(time_var_, "time", "standard_name", "time");
    put_text_att(time_var_, "time", "long_name", "simulated time");
    put_text_att(time_var_, "time", "axis", "T");

    for (const HistoryVariable& v : variables) {
      int id = -1;
      // netCDF itself rejects bad or duplicate names (NC_EBADNAME, NC_ENAMEINUSE); the
      // message names the variable.
      check(nc_def_var(ncid_, v.name.c_str(), NC_DOUBLE, 1, &dim_time, &id),
            "defining variable '" + v.name + "'");
      put_text_att(id, v.name, "units", v.units);
      put_text_att(id, v.name, "long_name", v.long_name);
      for (const auto& [att, values] : v.attributes)
        check(nc_put_att_double(ncid_, id, att.c_str(), NC_DOUBLE, values.size(), values.data()),
              "writing attribute " + att + " of " + v.name);
      var_ids_.push_back(id);
    }
    check(nc_enddef(ncid_), "finishing the header definition");
    check(nc_sync(ncid_), "syncing the header");
  } catch (...) {
    // nc_close, not nc_abort: aborting a file in define mode unlinks the path, which
    // must never happen to a device node such as /dev/null given as the output.
    if (ncid_ >= 0) nc_close(ncid_);
    ncid_ = -1;
    throw;
  }
}

HistoryWriter::~HistoryWriter() {
  // Errors on close are lost here; every row was already synced, and callers that need
  // to know call close() themselves.
  try {
    close();
  } catch (...) {
  }
}

void HistoryWriter::append(double time, const std::vector<double>& values) {
  if (ncid_ < 0) throw std::logic_error("History output '" + path_ + "': append after close");
  if (values.size() != var_ids_.size())
    throw std::invalid_argument("History output '" + path_ + "', row " +
                                std::to_string(rows_) + ": " + std::to_string(values.size()) +
                                " values for " + std::to_string(var_ids_.size()) +
                                " variables");
  const size_t rec = static_cast<size_t>(rows_);
  auto check = [&](int status, int varid) {
    if (status == NC_NOERR) return;
    char name[NC_MAX_NAME + 1] = "?";
    nc_inq_varname(ncid_, varid, name);
    throw_output_error(path_, status, "row " + std::to_string(rows_) + ", variable " + name);
  };
  for (size_t k = 0; k < values.size(); ++k)
    check(nc_put_var1_double(ncid_, var_ids_[k], &rec, &values[k]), var_ids_[k]);
  check(nc_put_var1_double(ncid_, time_var_, &rec, &time), time_var_);
  const int status = nc_sync(ncid_);
  if (status != NC_NOERR)
    throw_output_error(path_, status, "row " + std::to_string(rows_) + ", sync");
  ++rows_;
}

void HistoryWriter::close() {
  if (ncid_ < 0) return;
  const int id = std::exchange(ncid_, -1);
  const int status = nc_close(id);
  if (status != NC_NOERR) throw_output_error(path_, status, "closing the file");
}

}  // namespace fdem::io
