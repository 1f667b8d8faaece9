#include "io/events_writer.hpp"

#include <fcntl.h>
#include <netcdf.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "base/errors.hpp"

namespace fdem::io {

namespace {

// The catalogue's variables, in the order they are defined and written.
enum BreakVar { B_TIME, B_X, B_Y, B_LENGTH, B_MODE, B_ENERGY, B_CE4, B_TRI_A, B_TRI_B, B_JOINT, B_GRAIN, B_COUNT };
enum EventVar { E_START, E_END, E_X, E_Y, E_BREAKS, E_ENERGY, E_MAGNITUDE, E_COUNT };

struct VarSpec {
  const char* name;
  nc_type type;
  const char* units;
  const char* long_name;
};

const VarSpec kBreakVars[B_COUNT] = {
    {"break_time", NC_DOUBLE, "s", "time of the step in which the CE4 broke"},
    {"break_x", NC_DOUBLE, "m", "x of the CE4's midpoint (mean of its four nodes) when it broke"},
    {"break_y", NC_DOUBLE, "m", "y of the CE4's midpoint (mean of its four nodes) when it broke"},
    {"break_length", NC_DOUBLE, "m", "initial length h of the CE4"},
    {"break_mode", NC_INT, "1", "failure mode: 1 mode I (opening), 2 mode II (slip), 3 mixed"},
    {"break_energy", NC_DOUBLE, "J",
     "fracture energy the CE4 dissipated up to and including the step it broke (per the case thickness)"},
    {"break_ce4", NC_INT, "1", "CE4 index, 0-based (element break_ce4 + 1 of the Exodus cohesive block)"},
    {"break_tri_a", NC_INT, "1", "first triangle of the CE4, 0-based (Exodus TRI3 element break_tri_a + 1)"},
    {"break_tri_b", NC_INT, "1", "second triangle of the CE4, 0-based (Exodus TRI3 element break_tri_b + 1)"},
    {"break_joint", NC_INT, "1", "the [[joint]] the CE4 lies on, 0-based (joint[break_joint] of the case); -1 not on a joint"},
    {"break_grain_boundary", NC_INT, "1",
     "[grains]: 1 the CE4 lies on a grain boundary, 0 inside a grain, -1 not between two grains"},
};

const VarSpec kEventVars[E_COUNT] = {
    {"event_start", NC_DOUBLE, "s", "time of the event's first break"},
    {"event_end", NC_DOUBLE, "s", "time of the event's last break"},
    {"event_x", NC_DOUBLE, "m", "x of the event's centroid (mean of its breaks' midpoints)"},
    {"event_y", NC_DOUBLE, "m", "y of the event's centroid (mean of its breaks' midpoints)"},
    {"event_breaks", NC_INT, "1", "number of breaks in the event"},
    {"event_energy", NC_DOUBLE, "J", "sum of the break_energy of the event's breaks (fracture energy)"},
    {"event_magnitude", NC_DOUBLE, "1", "magnitude 2/3 (log10(event_energy) - 4.8); NaN where event_energy <= 0"},
};

void text_att(const NetcdfFile& f, int var, const char* name, const std::string& value) {
  f.check(nc_put_att_text(f.id(), var, name, value.size(), value.c_str()), std::string("writing attribute ") + name);
}

// Defines the global attributes and the catalogue (and the events when n_events > 0);
// returns the variable ids in `breaks` and `events`.
// Without grains the catalogue has no break_grain_boundary (its id stays -1).
void define(const NetcdfFile& f, const std::string& title, size_t n_events, bool grains, int breaks[B_COUNT],
            int events[E_COUNT]) {
  const int nc = f.id();
  text_att(f, NC_GLOBAL, "title", title);
  text_att(f, NC_GLOBAL, "Conventions", "CF-1.8");
  text_att(f, NC_GLOBAL, "source", "fdem-cl");
  text_att(f, NC_GLOBAL, "comment",
           "break catalogue: one record per CE4 that broke, sorted by (break_time, break_ce4); events: breaks "
           "within event_distance and event_window of each other, transitively (single linkage)");
  int dim_break = -1;
  f.check(nc_def_dim(nc, "break", NC_UNLIMITED, &dim_break), "defining dimension break");
  auto def = [&](const VarSpec& v, int dim, int* id) {
    f.check(nc_def_var(nc, v.name, v.type, 1, &dim, id), std::string("defining variable ") + v.name);
    text_att(f, *id, "units", v.units);
    text_att(f, *id, "long_name", v.long_name);
  };
  for (int k = 0; k < B_COUNT; ++k) {
    breaks[k] = -1;
    if (k != B_GRAIN || grains) def(kBreakVars[k], dim_break, &breaks[k]);
  }
  const int flags[3] = {1, 2, 3};
  f.check(nc_put_att_int(nc, breaks[B_MODE], "flag_values", NC_INT, 3, flags), "writing flag_values");
  text_att(f, breaks[B_MODE], "flag_meanings", "mode_I mode_II mixed");
  f.check(nc_put_att_text(nc, breaks[B_TIME], "standard_name", 4, "time"), "writing standard_name");
  if (n_events > 0) {
    int dim_event = -1;
    f.check(nc_def_dim(nc, "event", n_events, &dim_event), "defining dimension event");
    for (int k = 0; k < E_COUNT; ++k) def(kEventVars[k], dim_event, &events[k]);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    f.check(nc_put_att_double(nc, events[E_MAGNITUDE], "_FillValue", NC_DOUBLE, 1, &nan), "writing _FillValue");
  }
}

void write_breaks(const NetcdfFile& f, const int ids[B_COUNT], size_t first, const std::vector<BreakRecord>& r) {
  if (r.empty()) return;
  const size_t n = r.size();
  const size_t start = first, count = n;
  std::vector<double> d(n);
  std::vector<int> i(n);
  auto put_d = [&](int var, double BreakRecord::*m) {
    for (size_t k = 0; k < n; ++k) d[k] = r[k].*m;
    f.check(nc_put_vara_double(f.id(), ids[var], &start, &count, d.data()),
            std::string("writing ") + kBreakVars[var].name);
  };
  auto put_i = [&](int var, auto get) {
    for (size_t k = 0; k < n; ++k) i[k] = static_cast<int>(get(r[k]));
    f.check(nc_put_vara_int(f.id(), ids[var], &start, &count, i.data()), std::string("writing ") + kBreakVars[var].name);
  };
  put_d(B_TIME, &BreakRecord::time);
  put_d(B_X, &BreakRecord::x);
  put_d(B_Y, &BreakRecord::y);
  put_d(B_LENGTH, &BreakRecord::length);
  put_i(B_MODE, [](const BreakRecord& b) { return b.mode; });
  put_d(B_ENERGY, &BreakRecord::energy);
  put_i(B_CE4, [](const BreakRecord& b) { return b.ce4; });
  put_i(B_TRI_A, [](const BreakRecord& b) { return b.tri_a; });
  put_i(B_TRI_B, [](const BreakRecord& b) { return b.tri_b; });
  put_i(B_JOINT, [](const BreakRecord& b) { return b.joint; });
  if (ids[B_GRAIN] >= 0) put_i(B_GRAIN, [](const BreakRecord& b) { return b.grain_boundary; });
}

}  // namespace

EventsWriter::EventsWriter(const std::string& path, const std::string& title, bool grains)
    : path_(path), title_(title), grains_(grains), file_("Events output", path) {
  file_.create();
  int breaks[B_COUNT], events[E_COUNT];
  define(file_, title_, 0, grains_, breaks, events);
  file_.check(nc_enddef(file_.id()), "finishing the header definition");
  file_.check(nc_sync(file_.id()), "syncing the header");
}

void EventsWriter::append(const std::vector<BreakRecord>& records) {
  if (records.empty()) return;
  if (!file_.is_open()) throw OutputError("Events output '" + path_ + "': append after close");
  int ids[B_COUNT];
  for (int k = 0; k < B_COUNT; ++k) {
    ids[k] = -1;
    if (k != B_GRAIN || grains_) file_.check(nc_inq_varid(file_.id(), kBreakVars[k].name, &ids[k]), "finding variables");
  }
  write_breaks(file_, ids, written_, records);
  file_.check(nc_sync(file_.id()), "syncing breaks " + std::to_string(written_));
  written_ += records.size();
}

void EventsWriter::finish(const std::vector<BreakRecord>& all, const std::vector<EventRecord>& events,
                          const EventRule& rule) {
  file_.close();
  const std::string tmp = path_ + ".tmp";
  {
    NetcdfFile out("Events output", tmp);
    out.create();
    int breaks[B_COUNT], ev[E_COUNT];
    define(out, title_, events.size(), grains_, breaks, ev);
    const int nc = out.id();
    out.check(nc_put_att_double(nc, NC_GLOBAL, "event_distance", NC_DOUBLE, 1, &rule.distance), "writing event_distance");
    text_att(out, NC_GLOBAL, "event_distance_units", "m");
    out.check(nc_put_att_double(nc, NC_GLOBAL, "event_window", NC_DOUBLE, 1, &rule.window), "writing event_window");
    text_att(out, NC_GLOBAL, "event_window_units", "s");
    const int count = static_cast<int>(events.size());
    out.check(nc_put_att_int(nc, NC_GLOBAL, "event_count", NC_INT, 1, &count), "writing event_count");
    out.check(nc_enddef(nc), "finishing the header definition");
    write_breaks(out, breaks, 0, all);
    if (!events.empty()) {
      const size_t n = events.size();
      std::vector<double> d(n);
      auto put_d = [&](int var, double EventRecord::*m) {
        for (size_t k = 0; k < n; ++k) d[k] = events[k].*m;
        out.check(nc_put_var_double(nc, ev[var], d.data()), std::string("writing ") + kEventVars[var].name);
      };
      put_d(E_START, &EventRecord::start);
      put_d(E_END, &EventRecord::end);
      put_d(E_X, &EventRecord::x);
      put_d(E_Y, &EventRecord::y);
      std::vector<int> b(n);
      for (size_t k = 0; k < n; ++k) b[k] = static_cast<int>(events[k].breaks);
      out.check(nc_put_var_int(nc, ev[E_BREAKS], b.data()), "writing event_breaks");
      put_d(E_ENERGY, &EventRecord::energy);
      put_d(E_MAGNITUDE, &EventRecord::magnitude);
    }
    out.close();
  }
  // Data on the disk before the rename makes it visible.
  const int fd = ::open(tmp.c_str(), O_RDONLY);
  if (fd < 0 || ::fsync(fd) != 0) {
    if (fd >= 0) ::close(fd);
    throw OutputError("Events output '" + path_ + "': cannot sync " + tmp);
  }
  ::close(fd);
  std::error_code ec;
  std::filesystem::rename(tmp, path_, ec);
  if (ec) throw OutputError("Events output '" + path_ + "': cannot put " + tmp + " in its place: " + ec.message());
  written_ = all.size();
}

std::vector<BreakRecord> read_break_records(const std::string& path, double t_max) {
  int nc = -1;
  if (nc_open(path.c_str(), NC_NOWRITE, &nc) != NC_NOERR) throw OutputError("cannot read events file '" + path + "'");
  std::vector<BreakRecord> out;
  int dim = -1;
  size_t n = 0;
  bool ok = nc_inq_dimid(nc, "break", &dim) == NC_NOERR && nc_inq_dimlen(nc, dim, &n) == NC_NOERR;
  std::vector<double> d[6];
  std::vector<int> i[4];
  const char* dn[6] = {"break_time", "break_x", "break_y", "break_length", "break_energy", nullptr};
  for (int k = 0; ok && k < 5; ++k) {
    int v = -1;
    d[k].resize(n);
    ok = nc_inq_varid(nc, dn[k], &v) == NC_NOERR && (n == 0 || nc_get_var_double(nc, v, d[k].data()) == NC_NOERR);
  }
  const char* in[4] = {"break_mode", "break_ce4", "break_tri_a", "break_tri_b"};
  for (int k = 0; ok && k < 4; ++k) {
    int v = -1;
    i[k].resize(n);
    ok = nc_inq_varid(nc, in[k], &v) == NC_NOERR && (n == 0 || nc_get_var_int(nc, v, i[k].data()) == NC_NOERR);
  }
  // break_joint came later ([[joint]]): an older file's breaks are on no joint.
  std::vector<int> joint(n, -1);
  if (int v = -1; ok && n > 0 && nc_inq_varid(nc, "break_joint", &v) == NC_NOERR)
    ok = nc_get_var_int(nc, v, joint.data()) == NC_NOERR;
  // break_grain_boundary: [grains] cases only.
  std::vector<int> grain(n, -1);
  if (int v = -1; ok && n > 0 && nc_inq_varid(nc, "break_grain_boundary", &v) == NC_NOERR)
    ok = nc_get_var_int(nc, v, grain.data()) == NC_NOERR;
  nc_close(nc);
  if (!ok) throw OutputError("events file '" + path + "' has no readable break catalogue");
  for (size_t r = 0; r < n; ++r) {
    if (!(d[0][r] <= t_max + 1e-12 * std::fabs(t_max))) continue;
    out.push_back(BreakRecord{d[0][r], d[1][r], d[2][r], d[3][r], d[4][r], i[0][r], i[1][r], i[2][r], i[3][r], joint[r], grain[r]});
  }
  return out;
}

}  // namespace fdem::io
