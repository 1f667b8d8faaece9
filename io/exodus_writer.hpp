// Exodus II output written with plain netCDF-C (classic 64-bit-offset format, synced
// after every frame so that a killed run leaves every finished frame readable).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/netcdf_file.hpp"

namespace fdem::io {

struct ExodusBlock {
  std::string name;               // element block name (material name for TRI3 blocks)
  std::string elem_type;          // "TRI3", "QUAD4", ...
  int nodes_per_elem = 3;
  std::vector<int> connectivity;  // 0-based node indices, nodes_per_elem per element
};

// How frame values (nodal and element variables) are stored; coordinates, connectivity
// and times are always as they are (double, int). The default is the crash-safe classic
// file of doubles.
struct ExodusOptions {
  bool float_values = false;  // [output] precision = "float": NC_FLOAT frame variables
  bool compress = false;      // [output] compress: netCDF-4 (HDF5), shuffle + deflate level 1
};

class ExodusWriter {
 public:
  // Creates (overwrites) `path` and writes the fixed part: coordinates, blocks, names.
  // Throws fdem::OutputError naming the path on any netCDF failure.
  ExodusWriter(const std::string& path, const std::string& title,
               const std::vector<double>& x, const std::vector<double>& y,
               const std::vector<ExodusBlock>& blocks,
               const std::vector<std::string>& nodal_var_names,
               const std::vector<std::string>& elem_var_names, const ExodusOptions& options = {});
  ExodusWriter(const ExodusWriter&) = delete;
  ExodusWriter& operator=(const ExodusWriter&) = delete;

  // Appends one frame. nodal[k] has num_nodes values of nodal variable k; elem[k][b]
  // has the values of element variable k on block b. Syncs the file to disk.
  void write_frame(double time, const std::vector<std::vector<double>>& nodal,
                   const std::vector<std::vector<std::vector<double>>>& elem);

  int frames_written() const { return frames_; }
  // The digest of every frame written (io::frame_digest of what the file holds).
  const std::vector<std::uint64_t>& frame_digests() const { return digests_; }
  size_t node_count() const { return num_nodes_; }
  const std::vector<size_t>& block_sizes() const { return block_sizes_; }
  size_t nodal_variable_count() const { return nodal_var_names_.size(); }
  size_t element_variable_count() const { return elem_var_names_.size(); }
  const std::string& path() const { return file_.path(); }
  void close() { file_.close(); }  // idempotent; the destructor closes and never throws
  void moved_to(const std::string& path) { file_.moved_to(path); }

 private:
  NetcdfFile file_;
  int frames_ = 0;
  bool float_values_ = false;
  std::vector<std::uint64_t> digests_;
  size_t num_nodes_ = 0;
  std::vector<size_t> block_sizes_;
  int time_var_ = -1;
  std::vector<int> nodal_var_ids_;
  std::vector<std::vector<int>> elem_var_ids_;  // [var][block]
  std::vector<std::string> nodal_var_names_;  // for error messages
  std::vector<std::string> elem_var_names_;
};

// The digest of a frame as an Exodus file holds it: its time, then the nodal variables,
// then the element variables block by block (RecordDigest). `as_float`: the values are
// stored as NC_FLOAT ([output] precision = "float"); values read back are already so.
std::uint64_t frame_digest(double time, const std::vector<std::vector<double>>& nodal,
                           const std::vector<std::vector<std::vector<double>>>& elem, bool as_float = false);

}  // namespace fdem::io
