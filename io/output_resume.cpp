#include "io/output_resume.hpp"

#include <netcdf.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <vector>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace fdem::io {

namespace {

// What a refusal says after naming the record: the ways on.
constexpr const char* kWaysOn =
    "; restore the file, continue from an earlier checkpoint whose records it still holds, or move it away: "
    "--restart then starts a new one at the checkpoint's step";

InputError refused(const std::string& path, const std::string& why) {
  return InputError("cannot continue '" + path + "': " + why + kWaysOn);
}

struct Reader {
  int id = -1;
  std::string path;
  explicit Reader(const std::string& p) : path(p) {
    if (int s = nc_open(p.c_str(), NC_NOWRITE, &id); s != NC_NOERR) {
      id = -1;
      throw refused(p, std::string("it cannot be opened (") + nc_strerror(s) + ")");
    }
  }
  ~Reader() {
    if (id >= 0) nc_close(id);
  }
  int var(const std::string& name) const {
    int v = -1;
    return nc_inq_varid(id, name.c_str(), &v) == NC_NOERR ? v : -1;
  }
  size_t dimension(const char* name) const {
    int d = -1;
    size_t n = 0;
    if (nc_inq_dimid(id, name, &d) != NC_NOERR || nc_inq_dimlen(id, d, &n) != NC_NOERR) return 0;
    return n;
  }
  // The records of the unlimited dimension of variable `v`.
  size_t records(int v) const {
    int dims[NC_MAX_VAR_DIMS];
    size_t n = 0;
    if (v < 0 || nc_inq_vardimid(id, v, dims) != NC_NOERR || nc_inq_dimlen(id, dims[0], &n) != NC_NOERR) return 0;
    return n;
  }
  // Record `rec` of `v` (`count` values); false when netCDF cannot read it.
  bool read(int v, size_t rec, size_t count, double* out) const {
    const size_t start[2] = {rec, 0}, len[2] = {1, count};
    return nc_get_vara_double(id, v, start, len, out) == NC_NOERR;
  }
};

// "frame 3 of 22 (t = 1.5e-05 s as read)"
std::string record_name(const char* kind, size_t r, size_t held, double t) {
  return std::string(kind) + " " + std::to_string(r) + " of " + std::to_string(held) +
         " (t = " + format_number(t) + " s as read)";
}

// The first `written.size()` records must be there: more are those after the checkpoint.
void check_count(const std::string& path, const char* kinds, size_t held, size_t written) {
  if (held < written)
    throw refused(path, "it holds " + std::to_string(held) + " " + kinds + ", the checkpoint was written after " +
                            std::to_string(written) + " (the file was cut short or replaced)");
}

void check_record(const std::string& path, const char* kind, size_t r, size_t held, double t, bool readable,
                  std::uint64_t digest, const std::vector<std::uint64_t>& written) {
  if (!readable) throw refused(path, record_name(kind, r, held, t) + " cannot be read (the file is damaged)");
  if (digest != written[r])
    throw refused(path, record_name(kind, r, held, t) +
                            " is not the one the run wrote before its checkpoint (the file is damaged, zeroed in "
                            "part or cut short, or was written by another run)");
}

}  // namespace

std::string digests_text(const std::vector<std::uint64_t>& digests) {
  std::string out;
  out.reserve(digests.size() * 17);
  char hex[17];
  for (const auto d : digests) {
    std::snprintf(hex, sizeof hex, "%016" PRIx64, d);
    if (!out.empty()) out += ' ';
    out += hex;
  }
  return out;
}

std::vector<std::uint64_t> parse_digests(const std::string& text) {
  std::vector<std::uint64_t> out;
  for (size_t at = 0; at < text.size(); at += 17) {
    if (at + 16 > text.size() || (at + 16 < text.size() && text[at + 16] != ' '))
      throw std::invalid_argument("not a list of record digests");
    const std::string hex = text.substr(at, 16);
    char* stop = nullptr;
    const unsigned long long d = std::strtoull(hex.c_str(), &stop, 16);
    if (stop != hex.c_str() + 16) throw std::invalid_argument("not a list of record digests");
    out.push_back(d);
  }
  return out;
}

int copy_history_rows(const std::string& from, HistoryWriter& to, const ResumeCopy& copy) {
  const Reader in(from);
  const int time_var = in.var("time");
  if (time_var < 0) throw refused(from, "it has no variable 'time' (not a history file)");
  const size_t held = in.records(time_var);
  check_count(from, "rows", held, copy.written.size());
  // The file's row variables in the order they were defined: the order of the digest.
  int nvars = 0;
  nc_inq_nvars(in.id, &nvars);
  std::vector<int> stored;
  std::vector<std::string> stored_names;
  int time_dim = -1;
  nc_inq_vardimid(in.id, time_var, &time_dim);
  for (int v = 0; v < nvars; ++v) {
    int ndims = 0, dims[NC_MAX_VAR_DIMS];
    char name[NC_MAX_NAME + 1];
    if (v == time_var || nc_inq_var(in.id, v, name, nullptr, &ndims, dims, nullptr) != NC_NOERR) continue;
    if (ndims == 1 && dims[0] == time_dim) stored.push_back(v), stored_names.push_back(name);
  }
  // Where each of the new file's variables is in a row of the old one.
  const auto& names = to.variable_names();
  std::vector<int> column(names.size(), -1);
  for (size_t k = 0; k < names.size(); ++k)
    for (size_t j = 0; j < stored_names.size(); ++j)
      if (stored_names[j] == names[k]) column[k] = static_cast<int>(j);
  int rows = 0;
  std::vector<double> values(stored.size());
  for (size_t r = 0; r < copy.written.size(); ++r) {
    if (copy.stopped()) return -1;
    double t = std::numeric_limits<double>::quiet_NaN();
    bool readable = in.read(time_var, r, 1, &t);
    for (size_t j = 0; j < stored.size() && readable; ++j) readable = in.read(stored[j], r, 1, &values[j]);
    check_record(from, "row", r, held, t, readable, readable ? row_digest(t, values) : 0, copy.written);
    if (!copy.keep(t)) continue;
    ++rows;
    std::vector<double> row(names.size(), std::numeric_limits<double>::quiet_NaN());
    for (size_t k = 0; k < names.size(); ++k)
      if (column[k] >= 0) row[k] = values[column[k]];
    to.append(t, row);
  }
  return rows;
}

int copy_exodus_frames(const std::string& from, ExodusWriter& to, const ResumeCopy& copy) {
  const Reader in(from);
  const int time_var = in.var("time_whole");
  if (time_var < 0) throw refused(from, "it has no variable 'time_whole' (not an Exodus file)");
  const size_t held = in.records(time_var);
  check_count(from, "frames", held, copy.written.size());
  if (in.dimension("num_nodes") != to.node_count() || in.dimension("num_el_blk") != to.block_sizes().size() ||
      in.dimension("num_nod_var") != to.nodal_variable_count() ||
      in.dimension("num_elem_var") != to.element_variable_count())
    throw refused(from, "it has another mesh or other variables than this run writes");
  std::vector<int> nodal_vars;
  for (size_t k = 0; k < to.nodal_variable_count(); ++k) {
    nodal_vars.push_back(in.var("vals_nod_var" + std::to_string(k + 1)));
    if (nodal_vars.back() < 0) throw refused(from, "it has other nodal variables");
  }
  std::vector<std::vector<int>> elem_vars(to.element_variable_count());
  for (size_t k = 0; k < elem_vars.size(); ++k)
    for (size_t b = 0; b < to.block_sizes().size(); ++b) {
      elem_vars[k].push_back(in.var("vals_elem_var" + std::to_string(k + 1) + "eb" + std::to_string(b + 1)));
      if (elem_vars[k].back() < 0) throw refused(from, "it has other element variables");
    }
  int frames = 0;
  std::vector<std::vector<double>> nodal(nodal_vars.size(), std::vector<double>(to.node_count()));
  std::vector<std::vector<std::vector<double>>> elem(elem_vars.size());
  for (auto& var : elem)
    for (size_t n : to.block_sizes()) var.emplace_back(n);
  for (size_t f = 0; f < copy.written.size(); ++f) {
    if (copy.stopped()) return -1;
    double t = std::numeric_limits<double>::quiet_NaN();
    bool readable = in.read(time_var, f, 1, &t);
    for (size_t k = 0; k < nodal.size() && readable; ++k) readable = in.read(nodal_vars[k], f, to.node_count(), nodal[k].data());
    for (size_t k = 0; k < elem.size() && readable; ++k)
      for (size_t b = 0; b < elem[k].size() && readable; ++b)
        readable = in.read(elem_vars[k][b], f, elem[k][b].size(), elem[k][b].data());
    check_record(from, "frame", f, held, t, readable, readable ? frame_digest(t, nodal, elem) : 0, copy.written);
    if (!copy.keep(t)) continue;
    ++frames;
    to.write_frame(t, nodal, elem);
  }
  return frames;
}

int copy_fragment_frames(const std::string& from, FragmentWriter& to, const ResumeCopy& copy) {
  FragmentFrames in;
  try {
    in = read_fragment_file(from);
  } catch (const OutputError& e) {
    throw refused(from, std::string("it cannot be read (") + e.what() + ")");
  }
  const size_t held = in.time.size();
  check_count(from, "frames", held, copy.written.size());
  int frames = 0;
  for (size_t f = 0; f < copy.written.size(); ++f) {
    if (copy.stopped()) return -1;
    check_record(from, "frame", f, held, in.time[f], true, fragment_frame_digest(in.time[f], in.fragments[f]),
                 copy.written);
    if (!copy.keep(in.time[f])) continue;
    ++frames;
    to.write_frame(in.time[f], in.fragments[f]);
  }
  return frames;
}

}  // namespace fdem::io
