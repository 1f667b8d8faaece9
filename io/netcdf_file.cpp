#include "io/netcdf_file.hpp"

#include <netcdf.h>

#include <filesystem>
#include <utility>

#include "base/errors.hpp"

namespace fdem::io {

static_assert(NC_NOERR == 0, "NetcdfFile::check compares with 0");

NetcdfFile::NetcdfFile(std::string kind, std::string path)
    : kind_(std::move(kind)), path_(std::move(path)) {}

NetcdfFile::~NetcdfFile() {
  if (id_ >= 0) nc_close(id_);
}

void NetcdfFile::create(bool netcdf4) {
  std::error_code ec;
  const auto st = std::filesystem::status(path_, ec);
  if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    throw OutputError(kind_ + " '" + path_ + "': exists and is not a regular file");
  check(nc_create(path_.c_str(), NC_CLOBBER | (netcdf4 ? NC_NETCDF4 : NC_64BIT_OFFSET), &id_), "creating the file");
  // Each frame or row writes every variable, so pre-filling records is wasted I/O.
  int old_fill = 0;
  check(nc_set_fill(id_, NC_NOFILL, &old_fill), "setting fill mode");
}

void NetcdfFile::close() {
  if (id_ < 0) return;
  const int id = std::exchange(id_, -1);
  check(nc_close(id), "closing the file");
}

void NetcdfFile::fail(int status, const std::string& what) const {
  throw OutputError(kind_ + " '" + path_ + "': " + nc_strerror(status) + " (" + what + ")");
}

}  // namespace fdem::io
