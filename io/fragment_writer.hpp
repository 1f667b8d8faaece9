// The pieces of the body at every frame, OUT/NAME_fragments.nc: a CF-style contiguous
// ragged array over one unlimited dimension `fragment_record` (classic 64-bit-offset
// netCDF, synced after every frame like the other writers; the classic format has one
// unlimited dimension, so the frame of each record is a variable of the record).
// Layout in docs/case-format.md ("Fragments file").
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/netcdf_file.hpp"

namespace fdem::io {

struct FragmentRecord {
  int id = 0;            // smallest triangle index of the piece (0-based; written 1-based)
  int triangles = 0;     // triangles in the piece
  double area = 0;       // current area [m²]
  double mass = 0;       // [kg]
  double x = 0, y = 0;   // centre of mass [m]
  double diameter = 0;   // equivalent diameter sqrt(4 area / π) [m]
};

class FragmentWriter {
 public:
  // Creates (overwrites) `path` with the header. Throws fdem::OutputError naming the path.
  FragmentWriter(const std::string& path, const std::string& title);
  FragmentWriter(const FragmentWriter&) = delete;
  FragmentWriter& operator=(const FragmentWriter&) = delete;

  // Appends one frame's pieces (at least one; in increasing id) and syncs.
  void write_frame(double time, const std::vector<FragmentRecord>& fragments);
  int frames_written() const { return frames_; }
  size_t records_written() const { return records_; }
  // The digest of every frame written (io::fragment_frame_digest).
  const std::vector<std::uint64_t>& frame_digests() const { return digests_; }
  const std::string& path() const { return file_.path(); }
  void close() { file_.close(); }  // idempotent; the destructor closes and never throws
  void moved_to(const std::string& path) { file_.moved_to(path); }

 private:
  NetcdfFile file_;
  int frames_ = 0;
  std::vector<std::uint64_t> digests_;
  size_t records_ = 0;
  int frame_var_ = -1, time_var_ = -1, id_var_ = -1, count_var_ = -1;
  int area_var_ = -1, mass_var_ = -1, x_var_ = -1, y_var_ = -1, diameter_var_ = -1;
};

// Frames of a fragments file as read back (for restarts and tests): times, and each
// frame's records in file order.
struct FragmentFrames {
  std::vector<double> time;
  std::vector<std::vector<FragmentRecord>> fragments;
};
// Reads `path` (OutputError when missing or not a fragments file).
FragmentFrames read_fragment_file(const std::string& path);

// The digest of one frame's records as the file holds them: the time, then each record's
// id, triangles, area, mass, x, y and diameter.
std::uint64_t fragment_frame_digest(double time, const std::vector<FragmentRecord>& fragments);

}  // namespace fdem::io
