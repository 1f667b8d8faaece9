#include "io/exodus_writer.hpp"

#include <netcdf.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <stdexcept>

#include "base/errors.hpp"

namespace fdem::io {

namespace {

// Exodus names are stored in fixed-width char arrays: 32 characters and a NUL.
constexpr size_t kMaxNameLength = 32;
constexpr size_t kLenName = kMaxNameLength + 1;
constexpr size_t kLenString = 33;
constexpr size_t kLenLine = 81;  // the title is one "line" of 80 characters
// The Exodus file-format version recorded in the file; readers only insist on >= 2.0.
constexpr float kExodusVersion = 5.0f;

void check_name(const std::string& name, const std::string& kind) {
  if (name.empty())
    throw std::invalid_argument("Exodus output: empty " + kind + " name");
  if (name.size() > kMaxNameLength)
    throw std::invalid_argument("Exodus output: " + kind + " name '" + name + "' has " +
                                std::to_string(name.size()) + " characters, at most " +
                                std::to_string(kMaxNameLength) + " fit");
}

void check_unique(const std::vector<std::string>& names, const std::string& kind) {
  std::set<std::string> seen;
  for (const auto& n : names) {
    check_name(n, kind);
    if (!seen.insert(n).second)
      throw std::invalid_argument("Exodus output: " + kind + " name '" + n +
                                  "' appears twice");
  }
}

// Names as one row-major char block, each row NUL-padded to len_name, the layout of a
// (count, len_name) netCDF char variable.
std::vector<char> padded_names(const std::vector<std::string>& names) {
  std::vector<char> buf(names.size() * kLenName, '\0');
  for (size_t i = 0; i < names.size(); ++i)
    std::memcpy(buf.data() + i * kLenName, names[i].data(), names[i].size());
  return buf;
}

}  // namespace

ExodusWriter::ExodusWriter(const std::string& path, const std::string& title,
                           const std::vector<double>& x, const std::vector<double>& y,
                           const std::vector<ExodusBlock>& blocks,
                           const std::vector<std::string>& nodal_var_names,
                           const std::vector<std::string>& elem_var_names, const ExodusOptions& options)
    : file_("Exodus output", path),
      num_nodes_(x.size()),
      float_values_(options.float_values),
      nodal_var_names_(nodal_var_names),
      elem_var_names_(elem_var_names) {
  // Validate everything before touching the file so that bad input never clobbers an
  // existing output. A zero length would make netCDF define a second unlimited
  // dimension, which the classic format refuses, hence the non-empty rules.
  if (x.size() != y.size())
    throw std::invalid_argument("Exodus output: " + std::to_string(x.size()) +
                                " x coordinates but " + std::to_string(y.size()) +
                                " y coordinates");
  if (x.empty()) throw std::invalid_argument("Exodus output: the mesh has no nodes");
  if (blocks.empty())
    throw std::invalid_argument("Exodus output: the mesh has no element blocks");
  std::vector<std::string> block_names;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const ExodusBlock& blk = blocks[b];
    const std::string label = "block " + std::to_string(b + 1) + " '" + blk.name + "'";
    if (blk.nodes_per_elem <= 0)
      throw std::invalid_argument("Exodus output: " + label + " has nodes_per_elem " +
                                  std::to_string(blk.nodes_per_elem));
    if (blk.connectivity.empty())
      throw std::invalid_argument("Exodus output: " + label +
                                  " has no elements (leave empty blocks out)");
    if (blk.connectivity.size() % static_cast<size_t>(blk.nodes_per_elem) != 0)
      throw std::invalid_argument("Exodus output: " + label + " connectivity length " +
                                  std::to_string(blk.connectivity.size()) +
                                  " is not a multiple of " +
                                  std::to_string(blk.nodes_per_elem));
    for (int n : blk.connectivity)
      if (n < 0 || static_cast<size_t>(n) >= num_nodes_)
        throw std::invalid_argument("Exodus output: " + label + " refers to node " +
                                    std::to_string(n) + " of " +
                                    std::to_string(num_nodes_));
    check_name(blk.elem_type, "element type of " + label);
    block_names.push_back(blk.name);
    block_sizes_.push_back(blk.connectivity.size() / static_cast<size_t>(blk.nodes_per_elem));
  }
  check_unique(block_names, "element block");
  check_unique(nodal_var_names, "nodal variable");
  check_unique(elem_var_names, "element variable");

  const size_t num_blocks = blocks.size();
  size_t num_elem = 0;
  for (size_t n : block_sizes_) num_elem += n;

  // A failure below leaves file_ to close the file: members are destroyed when a
  // constructor throws.
  file_.create(options.compress);
  const int nc = file_.id();
  auto check = [&](int status, const std::string& what) { file_.check(status, what); };

  auto put_int_att = [&](const char* name, int value) {
    check(nc_put_att_int(nc, NC_GLOBAL, name, NC_INT, 1, &value),
          std::string("writing global attribute ") + name);
  };
  auto put_float_att = [&](const char* name, float value) {
    check(nc_put_att_float(nc, NC_GLOBAL, name, NC_FLOAT, 1, &value),
          std::string("writing global attribute ") + name);
  };
  put_float_att("api_version", kExodusVersion);
  put_float_att("version", kExodusVersion);
  put_int_att("floating_point_word_size", 8);
  put_int_att("file_size", 1);
  put_int_att("maximum_name_length", static_cast<int>(kMaxNameLength));
  put_int_att("int64_status", 0);
  // The title is descriptive only; longer ones are cut to the Exodus line length.
  const std::string short_title = title.substr(0, kLenLine - 1);
  check(nc_put_att_text(nc, NC_GLOBAL, "title", short_title.size(), short_title.c_str()),
        "writing global attribute title");

  auto def_dim = [&](const std::string& name, size_t len) {
    int id = -1;
    check(nc_def_dim(nc, name.c_str(), len, &id), "defining dimension " + name);
    return id;
  };
  auto def_var = [&](const std::string& name, nc_type type, std::vector<int> dims) {
    int id = -1;
    check(nc_def_var(nc, name.c_str(), type, static_cast<int>(dims.size()), dims.data(),
                     &id),
          "defining variable " + name);
    return id;
  };
  auto put_text_att = [&](int varid, const std::string& var, const char* name,
                          const std::string& value) {
    check(nc_put_att_text(nc, varid, name, value.size(), value.c_str()),
          "writing attribute " + std::string(name) + " of " + var);
  };

  def_dim("len_string", kLenString);
  def_dim("len_line", kLenLine);
  def_dim("four", 4);
  const int dim_len_name = def_dim("len_name", kLenName);
  const int dim_time = def_dim("time_step", NC_UNLIMITED);
  const int dim_num_dim = def_dim("num_dim", 2);
  const int dim_nodes = def_dim("num_nodes", num_nodes_);
  def_dim("num_elem", num_elem);
  const int dim_blocks = def_dim("num_el_blk", num_blocks);
  const int dim_nod_var =
      nodal_var_names.empty() ? -1 : def_dim("num_nod_var", nodal_var_names.size());
  const int dim_elem_var =
      elem_var_names.empty() ? -1 : def_dim("num_elem_var", elem_var_names.size());

  time_var_ = def_var("time_whole", NC_DOUBLE, {dim_time});
  const int var_eb_names = def_var("eb_names", NC_CHAR, {dim_blocks, dim_len_name});
  const int var_eb_status = def_var("eb_status", NC_INT, {dim_blocks});
  const int var_eb_prop1 = def_var("eb_prop1", NC_INT, {dim_blocks});
  // Readers identify blocks by this property; ParaView shows no variables without it.
  put_text_att(var_eb_prop1, "eb_prop1", "name", "ID");
  const int var_coordx = def_var("coordx", NC_DOUBLE, {dim_nodes});
  const int var_coordy = def_var("coordy", NC_DOUBLE, {dim_nodes});
  const int var_coor_names = def_var("coor_names", NC_CHAR, {dim_num_dim, dim_len_name});

  // A frame variable: float or double, deflated in a compressed file (shuffle helps
  // deflate with floating-point bytes; level 1 is about as small as higher levels here
  // and faster).
  const nc_type value_type = options.float_values ? NC_FLOAT : NC_DOUBLE;
  auto def_values = [&](const std::string& name, std::vector<int> dims) {
    const int id = def_var(name, value_type, std::move(dims));
    if (options.compress) check(nc_def_var_deflate(nc, id, 1, 1, 1), "compressing variable " + name);
    return id;
  };
  std::vector<int> var_connect(num_blocks);
  std::vector<int> dim_block_elems(num_blocks);
  for (size_t b = 0; b < num_blocks; ++b) {
    const std::string n = std::to_string(b + 1);
    dim_block_elems[b] = def_dim("num_el_in_blk" + n, block_sizes_[b]);
    const int dim_per_elem =
        def_dim("num_nod_per_el" + n, static_cast<size_t>(blocks[b].nodes_per_elem));
    var_connect[b] = def_var("connect" + n, NC_INT, {dim_block_elems[b], dim_per_elem});
    put_text_att(var_connect[b], "connect" + n, "elem_type", blocks[b].elem_type);
  }

  int var_name_nod_var = -1;
  if (!nodal_var_names.empty()) {
    var_name_nod_var = def_var("name_nod_var", NC_CHAR, {dim_nod_var, dim_len_name});
    for (size_t k = 0; k < nodal_var_names.size(); ++k)
      nodal_var_ids_.push_back(def_values("vals_nod_var" + std::to_string(k + 1), {dim_time, dim_nodes}));
  }
  int var_name_elem_var = -1;
  int var_elem_var_tab = -1;
  if (!elem_var_names.empty()) {
    var_name_elem_var = def_var("name_elem_var", NC_CHAR, {dim_elem_var, dim_len_name});
    var_elem_var_tab = def_var("elem_var_tab", NC_INT, {dim_blocks, dim_elem_var});
    elem_var_ids_.assign(elem_var_names.size(), std::vector<int>(num_blocks, -1));
    for (size_t k = 0; k < elem_var_names.size(); ++k)
      for (size_t b = 0; b < num_blocks; ++b)
        elem_var_ids_[k][b] =
            def_values("vals_elem_var" + std::to_string(k + 1) + "eb" + std::to_string(b + 1),
                       {dim_time, dim_block_elems[b]});
  }

  check(nc_enddef(nc), "finishing the header definition");

  // Fixed data.
  check(nc_put_var_double(nc, var_coordx, x.data()), "writing coordx");
  check(nc_put_var_double(nc, var_coordy, y.data()), "writing coordy");
  check(nc_put_var_text(nc, var_coor_names, padded_names({"x", "y"}).data()),
        "writing coor_names");
  check(nc_put_var_text(nc, var_eb_names, padded_names(block_names).data()),
        "writing eb_names");
  const std::vector<int> ones(std::max(num_blocks * elem_var_names.size(), num_blocks), 1);
  check(nc_put_var_int(nc, var_eb_status, ones.data()), "writing eb_status");
  std::vector<int> ids(num_blocks);
  for (size_t b = 0; b < num_blocks; ++b) ids[b] = static_cast<int>(b + 1);
  check(nc_put_var_int(nc, var_eb_prop1, ids.data()), "writing eb_prop1");
  for (size_t b = 0; b < num_blocks; ++b) {
    std::vector<int> one_based(blocks[b].connectivity);
    for (int& n : one_based) ++n;
    check(nc_put_var_int(nc, var_connect[b], one_based.data()),
          "writing connect" + std::to_string(b + 1));
  }
  if (var_name_nod_var >= 0)
    check(nc_put_var_text(nc, var_name_nod_var, padded_names(nodal_var_names).data()),
          "writing name_nod_var");
  if (var_name_elem_var >= 0) {
    check(nc_put_var_text(nc, var_name_elem_var, padded_names(elem_var_names).data()),
          "writing name_elem_var");
    // Every element variable exists on every block.
    check(nc_put_var_int(nc, var_elem_var_tab, ones.data()), "writing elem_var_tab");
  }
  check(nc_sync(nc), "syncing the header");
}

void ExodusWriter::write_frame(double time, const std::vector<std::vector<double>>& nodal,
                               const std::vector<std::vector<std::vector<double>>>& elem) {
  if (!file_.is_open())
    throw std::logic_error("Exodus output '" + path() + "': write_frame after close");
  const std::string frame = "frame " + std::to_string(frames_);
  if (nodal.size() != nodal_var_names_.size())
    throw std::invalid_argument("Exodus output '" + path() + "', " + frame + ": " +
                                std::to_string(nodal.size()) + " nodal variables given, " +
                                std::to_string(nodal_var_names_.size()) + " declared");
  if (elem.size() != elem_var_names_.size())
    throw std::invalid_argument("Exodus output '" + path() + "', " + frame + ": " +
                                std::to_string(elem.size()) + " element variables given, " +
                                std::to_string(elem_var_names_.size()) + " declared");
  for (size_t k = 0; k < nodal.size(); ++k)
    if (nodal[k].size() != num_nodes_)
      throw std::invalid_argument("Exodus output '" + path() + "', " + frame + ", variable " +
                                  nodal_var_names_[k] + ": " + std::to_string(nodal[k].size()) +
                                  " values for " + std::to_string(num_nodes_) + " nodes");
  for (size_t k = 0; k < elem.size(); ++k) {
    if (elem[k].size() != block_sizes_.size())
      throw std::invalid_argument("Exodus output '" + path() + "', " + frame + ", variable " +
                                  elem_var_names_[k] + ": values for " +
                                  std::to_string(elem[k].size()) + " blocks, the mesh has " +
                                  std::to_string(block_sizes_.size()));
    for (size_t b = 0; b < block_sizes_.size(); ++b)
      if (elem[k][b].size() != block_sizes_[b])
        throw std::invalid_argument(
            "Exodus output '" + path() + "', " + frame + ", variable " + elem_var_names_[k] +
            ", block " + std::to_string(b + 1) + ": " + std::to_string(elem[k][b].size()) +
            " values for " + std::to_string(block_sizes_[b]) + " elements");
  }

  const int nc = file_.id();
  const size_t rec = static_cast<size_t>(frames_);
  auto check = [&](int status, const std::string& what) { file_.check(status, frame + ", " + what); };
  for (size_t k = 0; k < nodal.size(); ++k) {
    const size_t start[2] = {rec, 0};
    const size_t count[2] = {1, num_nodes_};
    check(nc_put_vara_double(nc, nodal_var_ids_[k], start, count, nodal[k].data()),
          "variable " + nodal_var_names_[k]);
  }
  for (size_t k = 0; k < elem.size(); ++k)
    for (size_t b = 0; b < block_sizes_.size(); ++b) {
      const size_t start[2] = {rec, 0};
      const size_t count[2] = {1, block_sizes_[b]};
      check(nc_put_vara_double(nc, elem_var_ids_[k][b], start, count, elem[k][b].data()),
            "variable " + elem_var_names_[k] + " on block " + std::to_string(b + 1));
    }
  check(nc_put_var1_double(nc, time_var_, &rec, &time), "time_whole");
  // The record count on disk only grows here, so a killed run leaves whole frames.
  check(nc_sync(nc), "sync");
  ++frames_;
  digests_.push_back(frame_digest(time, nodal, elem, float_values_));
}

std::uint64_t frame_digest(double time, const std::vector<std::vector<double>>& nodal,
                           const std::vector<std::vector<std::vector<double>>>& elem, bool as_float) {
  RecordDigest d;
  d.add(time);
  auto add = [&](const std::vector<double>& v) {
    if (as_float) d.add_as_float(v.data(), v.size());
    else d.add(v.data(), v.size());
  };
  for (const auto& v : nodal) add(v);
  for (const auto& var : elem)
    for (const auto& block : var) add(block);
  return d.value();
}

}  // namespace fdem::io
