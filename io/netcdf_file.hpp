// One netCDF file open for writing, as io/exodus_writer.cpp and io/history_writer.cpp
// use it: classic 64-bit-offset format (crash-safe with nc_sync, unlike netCDF-4/HDF5),
// no pre-filling, closed exactly once. Every failure is an OutputError worded
// "<kind> '<path>': <netCDF's message> (<what was being done>)".
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

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
  // The file was renamed (a run's files are written under temporary names until its
  // first frame): messages name the new path.
  void moved_to(std::string path) { path_ = std::move(path); }
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

// The digest of one record (a frame, a history row) as it is stored: its time and its
// values in file order, each value as the double that reading it back gives (FNV-1a over
// 64-bit words). The writers keep one per record; a checkpoint lists those written up to
// it, and a restart compares them with the records it reads back (io/output_resume.hpp),
// so a damaged or cut-short earlier output is refused instead of copied. Not cryptographic.
class RecordDigest {
 public:
  void add(double value) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    hash_ = (hash_ ^ bits) * 1099511628211ull;
  }
  void add(const double* values, std::size_t count) {
    for (std::size_t k = 0; k < count; ++k) add(values[k]);
  }
  // Values stored as NC_FLOAT: what reading them back as doubles gives.
  void add_as_float(const double* values, std::size_t count) {
    for (std::size_t k = 0; k < count; ++k) add(static_cast<double>(static_cast<float>(values[k])));
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 1469598103934665603ull;
};

}  // namespace fdem::io
