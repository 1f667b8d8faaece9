// One netCDF file open for writing, as io/exodus_writer.cpp and io/history_writer.cpp
// use it: classic 64-bit-offset format (crash-safe with nc_sync, unlike netCDF-4/HDF5),
// no pre-filling, closed exactly once. Every failure is an OutputError worded
// "<kind> '<path>': <netCDF's message> (<what was being done>)".
#pragma once
#include <string>

namespace fdem::io {

class NetcdfFile {
 public:
  // Names the file; nothing is touched until create(). `kind` starts every message:
  // "Exodus output", "History output".
  NetcdfFile(std::string kind, std::string path);
  // Closes the file if still open, ignoring errors: whatever was synced is on disk, and
  // callers that need to know call close() themselves.
  ~NetcdfFile();
  NetcdfFile(const NetcdfFile&) = delete;
  NetcdfFile& operator=(const NetcdfFile&) = delete;

  // Creates (overwrites) the file, in define mode. A path that exists and is not a
  // regular file (/dev/null, a FIFO) is refused first: nc_create unlinks the path when
  // creation fails (seen with netCDF-C 4.9.0).
  // `netcdf4`: netCDF-4 (HDF5) instead, for compressed output ([output] compress); it is
  // not crash-safe (a kill in the middle of a write can leave the file unreadable).
  void create(bool netcdf4 = false);
  // Idempotent; throws OutputError when netCDF reports a failure. Never nc_abort:
  // aborting a file in define mode unlinks the path.
  void close();

  bool is_open() const { return id_ >= 0; }
  int id() const { return id_; }  // the netCDF id; -1 before create() and after close()
  const std::string& path() const { return path_; }

  // Throws the OutputError for a netCDF status other than NC_NOERR.
  void check(int status, const std::string& what) const {
    if (status != 0) fail(status, what);
  }
  [[noreturn]] void fail(int status, const std::string& what) const;

 private:
  std::string kind_, path_;
  int id_ = -1;
};

}  // namespace fdem::io
