// [[boundary]] and [[initial]] entries: prescribed motion, loads and initial velocities
// on Gmsh physical groups.
#include "io/case_tables.hpp"

namespace fdem::io::detail {
namespace {

// `pressure` is a number, or a table { times, values } of a piecewise linear pressure;
// `blast = { peak, rise, ratio }` is the pressure of Eq. 21.
void read_boundary_pressure(const TableReader& r, BoundaryConfig& b) {
  const toml::node* p = r.find("pressure");
  if (p && p->is_table()) {
    const TableReader t = subtable_reader(r, *p->as_table(), "pressure");
    const std::string& path = t.path();
    t.check_keys(kPressureTableKeys);
    PressureTable table{read_numbers(t, "times"), read_numbers(t, "values")};
    if (table.times.size() != table.values.size())
      t.fail("values", path + ": times has " + std::to_string(table.times.size()) + " entries but values has " +
                           std::to_string(table.values.size()) + "; give one value per time");
    for (std::size_t i = 1; i < table.times.size(); ++i)
      if (!(table.times[i] > table.times[i - 1]))
        t.fail("times", path + ".times must increase: times[" + std::to_string(i) + "] = " +
                            format_number(table.times[i], kDigits) + " follows " + format_number(table.times[i - 1], kDigits));
    b.pressure_table = table;
  } else if (p && !p->is_number()) {
    r.fail("pressure", r.key_path("pressure") + " must be a number or a table { times = [...], values = [...] }, found " +
                           describe(*p));
  } else {
    b.pressure = r.number("pressure");
  }
  if (const toml::table* t = subtable(r, "blast")) {
    const TableReader blast = subtable_reader(r, *t, "blast");
    blast.check_keys(kBlastKeys);
    b.blast = BlastConfig{blast.required_number("peak", kPositive), blast.required_number("rise", kPositive),
                          blast.required_number("ratio", Range{1.0, std::numeric_limits<double>::infinity(), true, false})};
  }
}

}  // namespace

BoundaryConfig read_boundary(const TableReader& r) {
  r.check_keys(kBoundaryKeys);
  BoundaryConfig b;
  b.region = r.required_string("region");
  check_region_name(r, "region", b.region);
  if (const toml::node* fix = r.find("fix")) {
    const std::vector<std::string> axes = *r.strings("fix");
    for (std::size_t i = 0; i < axes.size(); ++i) {
      bool& flag = axes[i] == "x" ? b.fix_x : b.fix_y;
      if (axes[i] != "x" && axes[i] != "y")
        r.ctx().fail(*fix->as_array()->get(i), r.key_path("fix") + "[" + std::to_string(i) +
                                                   "] = \"" + axes[i] +
                                                   "\" is not an axis (allowed: \"x\", \"y\")");
      if (flag) r.fail("fix", r.key_path("fix") + " lists \"" + axes[i] + "\" twice");
      flag = true;
    }
  }
  b.velocity = r.pair("velocity");
  b.traction = r.pair("traction");
  read_boundary_pressure(r, b);
  b.absorbing = r.boolean("absorbing").value_or(false);
  b.in_situ = r.boolean("in_situ").value_or(false);
  const bool loads = b.traction || b.pressure || b.pressure_table || b.blast || b.absorbing || b.in_situ;
  const bool motion = b.fix_x || b.fix_y || b.velocity;
  if (!loads && !motion)
    r.ctx().fail(r.table(), r.title() + " needs at least one of 'fix', 'velocity', 'traction', "
                                    "'pressure', 'blast', 'absorbing = true', 'in_situ = true'");
  // absorbing = false and in_situ = false are no load
  std::vector<const char*> kinds = {"traction", "pressure", "blast"};
  if (b.absorbing) kinds.push_back("absorbing");
  if (b.in_situ) kinds.push_back("in_situ");
  for (size_t i = 0; i < kinds.size(); ++i)
    for (size_t j = i + 1; j < kinds.size(); ++j) r.exclusive(kinds[i], kinds[j]);
  if (loads && motion) {
    const char* load = b.traction ? "traction" : b.blast ? "blast" : b.absorbing ? "absorbing" : b.in_situ ? "in_situ" : "pressure";
    r.fail(load, r.key_path(load) + " cannot be combined with fix or velocity in one [[boundary]]: use two entries");
  }
  for (int axis = 0; axis < 2; ++axis)
    if (b.velocity && (axis == 0 ? b.fix_x : b.fix_y) && (*b.velocity)[axis] != 0.0)
      r.fail("velocity", r.key_path("velocity") + "[" + std::to_string(axis) + "] = " +
                             format_number((*b.velocity)[axis], kDigits) + " but " + r.key_path("fix") +
                             " holds \"" + (axis == 0 ? "x" : "y") +
                             "\" still: it must be 0");
  if (r.has("rise") && !b.velocity && !b.traction && !b.pressure)
    r.fail("rise", r.key_path("rise") + " needs a velocity, traction or pressure to ramp" +
                       (b.blast ? " (a blast has its own rise inside: blast = { rise = ... })"
                        : b.pressure_table ? " (a pressure table gives the time dependence itself)"
                                           : ""));
  b.rise = r.number("rise", kNonNegative).value_or(0.0);
  return b;
}

InitialConfig read_initial(const TableReader& r) {
  r.check_keys(kInitialKeys);
  InitialConfig c;
  c.region = r.required_string("region");
  check_region_name(r, "region", c.region);
  if (!r.has("velocity")) r.missing("velocity");
  c.velocity = *r.pair("velocity");
  return c;
}

}  // namespace fdem::io::detail
