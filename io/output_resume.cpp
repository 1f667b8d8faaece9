#include "io/output_resume.hpp"

#include <netcdf.h>

#include <cmath>
#include <limits>
#include <vector>

#include "base/errors.hpp"

namespace fdem::io {

namespace {

struct Reader {
  int id = -1;
  std::string path;
  explicit Reader(const std::string& p) : path(p) {
    if (nc_open(p.c_str(), NC_NOWRITE, &id) != NC_NOERR)
      throw OutputError("cannot continue '" + p + "': it is missing or unreadable (run without --restart, or restore it)");
  }
  ~Reader() {
    if (id >= 0) nc_close(id);
  }
  int var(const std::string& name) const {
    int v = -1;
    return nc_inq_varid(id, name.c_str(), &v) == NC_NOERR ? v : -1;
  }
  std::vector<double> read(int v, size_t rec, size_t count) const {
    std::vector<double> out(count);
    const size_t start[2] = {rec, 0}, len[2] = {1, count};
    if (nc_get_vara_double(id, v, start, len, out.data()) != NC_NOERR)
      throw OutputError("cannot continue '" + path + "': a record cannot be read");
    return out;
  }
  std::vector<double> times(const char* name) const {
    const int v = var(name);
    int dim = -1;
    size_t n = 0;
    if (v < 0 || nc_inq_vardimid(id, v, &dim) != NC_NOERR || nc_inq_dimlen(id, dim, &n) != NC_NOERR)
      throw OutputError("cannot continue '" + path + "': it has no " + name);
    std::vector<double> t(n);
    if (n && nc_get_var_double(id, v, t.data()) != NC_NOERR) throw OutputError("cannot continue '" + path + "'");
    return t;
  }
};

// The same double the run computed for that step; a tiny margin for safety only.
bool kept(double t, double t_max) { return t <= t_max + 1e-12 * std::fabs(t_max); }

}  // namespace

int copy_history_rows(const std::string& from, HistoryWriter& to, double t_max,
                      const std::function<bool(double)>& keep) {
  const Reader in(from);
  const auto times = in.times("time");
  const auto& names = to.variable_names();
  std::vector<int> ids;
  for (const auto& n : names) ids.push_back(in.var(n));
  int rows = 0;
  for (size_t r = 0; r < times.size() && kept(times[r], t_max); ++r) {
    if (!keep(times[r])) continue;
    ++rows;
    std::vector<double> row(names.size(), std::numeric_limits<double>::quiet_NaN());
    for (size_t k = 0; k < ids.size(); ++k)
      if (ids[k] >= 0) nc_get_var1_double(in.id, ids[k], &r, &row[k]);
    to.append(times[r], row);
  }
  return rows;
}

int copy_exodus_frames(const std::string& from, ExodusWriter& to, double t_max,
                       const std::function<bool(double)>& keep) {
  const Reader in(from);
  const auto times = in.times("time_whole");
  int frames = 0;
  for (size_t f = 0; f < times.size() && kept(times[f], t_max); ++f) {
    if (!keep(times[f])) continue;
    ++frames;
    std::vector<std::vector<double>> nodal;
    for (size_t k = 0; k < to.nodal_variable_count(); ++k) {
      const int v = in.var("vals_nod_var" + std::to_string(k + 1));
      if (v < 0) throw OutputError("cannot continue '" + from + "': it has other nodal variables");
      nodal.push_back(in.read(v, f, to.node_count()));
    }
    std::vector<std::vector<std::vector<double>>> elem(to.element_variable_count());
    for (size_t k = 0; k < elem.size(); ++k)
      for (size_t b = 0; b < to.block_sizes().size(); ++b) {
        const int v = in.var("vals_elem_var" + std::to_string(k + 1) + "eb" + std::to_string(b + 1));
        if (v < 0) throw OutputError("cannot continue '" + from + "': it has other element variables");
        elem[k].push_back(in.read(v, f, to.block_sizes()[b]));
      }
    to.write_frame(times[f], nodal, elem);
  }
  return frames;
}

int copy_fragment_frames(const std::string& from, FragmentWriter& to, double t_max,
                         const std::function<bool(double)>& keep) {
  const FragmentFrames in = read_fragment_file(from);
  int frames = 0;
  for (size_t f = 0; f < in.time.size() && kept(in.time[f], t_max); ++f) {
    if (!keep(in.time[f])) continue;
    ++frames;
    to.write_frame(in.time[f], in.fragments[f]);
  }
  return frames;
}

}  // namespace fdem::io
