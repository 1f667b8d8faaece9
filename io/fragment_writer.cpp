#include "io/fragment_writer.hpp"

#include <netcdf.h>

#include <stdexcept>

#include "base/errors.hpp"

namespace fdem::io {

FragmentWriter::FragmentWriter(const std::string& path, const std::string& title) : file_("Fragment output", path) {
  file_.create();
  const int nc = file_.id();
  auto text = [&](int varid, const std::string& var, const char* name, const std::string& value) {
    file_.check(nc_put_att_text(nc, varid, name, value.size(), value.c_str()),
                "writing attribute " + std::string(name) + " of " + var);
  };
  text(NC_GLOBAL, "the file", "title", title);
  text(NC_GLOBAL, "the file", "Conventions", "CF-1.8");
  text(NC_GLOBAL, "the file", "source", "fdem-cl");
  text(NC_GLOBAL, "the file", "layout",
       "one record per fragment per frame; a frame's records are contiguous, in increasing fragment_id, "
       "and fragment_frame numbers the frames from 0 as the Exodus file's time steps");
  int dim = -1;
  file_.check(nc_def_dim(nc, "fragment_record", NC_UNLIMITED, &dim), "defining dimension fragment_record");
  auto def = [&](const char* name, nc_type type, const char* units, const char* long_name) {
    int id = -1;
    file_.check(nc_def_var(nc, name, type, 1, &dim, &id), std::string("defining variable ") + name);
    if (*units) text(id, name, "units", units);
    text(id, name, "long_name", long_name);
    return id;
  };
  frame_var_ = def("fragment_frame", NC_INT, "", "index of the frame (0-based; the Exodus time step - 1)");
  time_var_ = def("fragment_time", NC_DOUBLE, "s", "simulated time of the frame");
  text(time_var_, "fragment_time", "standard_name", "time");
  id_var_ = def("fragment_id", NC_INT, "",
                "fragment id: Exodus element number (1-based) of the fragment's first triangle, as FRAGMENT");
  count_var_ = def("fragment_triangles", NC_INT, "", "triangles in the fragment");
  area_var_ = def("fragment_area", NC_DOUBLE, "m2", "current area");
  mass_var_ = def("fragment_mass", NC_DOUBLE, "kg", "mass (density x reference area x thickness)");
  x_var_ = def("fragment_x", NC_DOUBLE, "m", "centre of mass, x, at the current positions");
  y_var_ = def("fragment_y", NC_DOUBLE, "m", "centre of mass, y, at the current positions");
  diameter_var_ = def("fragment_diameter", NC_DOUBLE, "m", "equivalent diameter sqrt(4 area / pi)");
  file_.check(nc_enddef(nc), "finishing the header definition");
  file_.check(nc_sync(nc), "syncing the header");
}

void FragmentWriter::write_frame(double time, const std::vector<FragmentRecord>& fragments) {
  if (!file_.is_open()) throw std::logic_error("Fragment output '" + path() + "': write_frame after close");
  if (fragments.empty())
    throw std::invalid_argument("Fragment output '" + path() + "', frame " + std::to_string(frames_) +
                                ": no fragments (a body has at least one)");
  const size_t n = fragments.size();
  std::vector<int> frame(n, frames_), id(n), count(n);
  std::vector<double> t(n, time), area(n), mass(n), x(n), y(n), diameter(n);
  for (size_t k = 0; k < n; ++k) {
    const auto& f = fragments[k];
    id[k] = f.id + 1, count[k] = f.triangles;
    area[k] = f.area, mass[k] = f.mass, x[k] = f.x, y[k] = f.y, diameter[k] = f.diameter;
  }
  const int nc = file_.id();
  const size_t start = records_, len = n;
  const std::string where = "frame " + std::to_string(frames_) + ", ";
  auto put_d = [&](int var, const std::vector<double>& v, const char* name) {
    file_.check(nc_put_vara_double(nc, var, &start, &len, v.data()), where + name);
  };
  auto put_i = [&](int var, const std::vector<int>& v, const char* name) {
    file_.check(nc_put_vara_int(nc, var, &start, &len, v.data()), where + name);
  };
  put_i(id_var_, id, "fragment_id");
  put_i(count_var_, count, "fragment_triangles");
  put_d(area_var_, area, "fragment_area");
  put_d(mass_var_, mass, "fragment_mass");
  put_d(x_var_, x, "fragment_x");
  put_d(y_var_, y, "fragment_y");
  put_d(diameter_var_, diameter, "fragment_diameter");
  put_d(time_var_, t, "fragment_time");
  put_i(frame_var_, frame, "fragment_frame");
  // The record count on disk grows only at the sync, so a killed run leaves whole frames.
  file_.check(nc_sync(nc), where + "sync");
  records_ += n;
  ++frames_;
  digests_.push_back(fragment_frame_digest(time, fragments));
}

std::uint64_t fragment_frame_digest(double time, const std::vector<FragmentRecord>& fragments) {
  RecordDigest d;
  d.add(time);
  for (const auto& f : fragments) {
    const double values[7] = {double(f.id), double(f.triangles), f.area, f.mass, f.x, f.y, f.diameter};
    d.add(values, 7);
  }
  return d.value();
}

FragmentFrames read_fragment_file(const std::string& path) {
  int nc = -1;
  if (nc_open(path.c_str(), NC_NOWRITE, &nc) != NC_NOERR)
    throw OutputError("cannot read fragments file '" + path + "': it is missing or unreadable");
  FragmentFrames out;
  auto fail = [&](const std::string& what) {
    nc_close(nc);
    throw OutputError("cannot read fragments file '" + path + "': " + what);
  };
  int dim = -1;
  size_t n = 0;
  if (nc_inq_dimid(nc, "fragment_record", &dim) != NC_NOERR || nc_inq_dimlen(nc, dim, &n) != NC_NOERR)
    fail("it has no dimension fragment_record");
  auto doubles = [&](const char* name) {
    int v = -1;
    std::vector<double> values(n);
    if (nc_inq_varid(nc, name, &v) != NC_NOERR || (n && nc_get_var_double(nc, v, values.data()) != NC_NOERR))
      fail(std::string("it has no readable variable ") + name);
    return values;
  };
  auto ints = [&](const char* name) {
    int v = -1;
    std::vector<int> values(n);
    if (nc_inq_varid(nc, name, &v) != NC_NOERR || (n && nc_get_var_int(nc, v, values.data()) != NC_NOERR))
      fail(std::string("it has no readable variable ") + name);
    return values;
  };
  const auto frame = ints("fragment_frame"), id = ints("fragment_id"), count = ints("fragment_triangles");
  const auto time = doubles("fragment_time"), area = doubles("fragment_area"), mass = doubles("fragment_mass");
  const auto x = doubles("fragment_x"), y = doubles("fragment_y"), diameter = doubles("fragment_diameter");
  nc_close(nc);
  for (size_t r = 0; r < n; ++r) {
    if (frame[r] != static_cast<int>(out.time.size()) - 1) {
      if (frame[r] != static_cast<int>(out.time.size()))
        throw OutputError("cannot read fragments file '" + path + "': record " + std::to_string(r) + " has frame " +
                          std::to_string(frame[r]) + " after frame " + std::to_string(out.time.size() - 1));
      out.time.push_back(time[r]);
      out.fragments.emplace_back();
    }
    out.fragments.back().push_back(FragmentRecord{id[r] - 1, count[r], area[r], mass[r], x[r], y[r], diameter[r]});
  }
  return out;
}

}  // namespace fdem::io
