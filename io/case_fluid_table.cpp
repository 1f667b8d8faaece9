// [fluid]: the fluid in the cracks (docs/case-format.md, "[fluid]").
#include "io/case_tables.hpp"

namespace fdem::io::detail {
namespace {

// `key` as a number (held from t = 0) or a table { times = [...], values = [...] },
// piecewise linear in time and held outside the times; values must satisfy `range`.
std::optional<PressureTable> number_or_table(const TableReader& r, std::string_view key, const Range& range,
                                             const char* unit) {
  const toml::node* n = r.find(key);
  if (!n) return std::nullopt;
  if (n->is_number()) return PressureTable{{0.0}, {*r.number(key, range)}};
  if (!n->is_table())
    r.fail(key, r.key_path(key) + " must be a number (" + unit + ") or a table { times = [...], values = [...] }, found " +
                    describe(*n));
  const TableReader t = subtable_reader(r, *n->as_table(), key);
  t.check_keys(kPressureTableKeys);
  PressureTable table{read_numbers(t, "times"), read_numbers(t, "values")};
  if (table.times.empty()) t.fail("times", t.path() + ".times is empty; give at least one time");
  if (table.times.size() != table.values.size())
    t.fail("values", t.path() + ": times has " + std::to_string(table.times.size()) + " entries but values has " +
                         std::to_string(table.values.size()) + "; give one value per time");
  for (std::size_t i = 1; i < table.times.size(); ++i)
    if (!(table.times[i] > table.times[i - 1]))
      t.fail("times", t.path() + ".times must increase: times[" + std::to_string(i) + "] = " +
                          format_number(table.times[i], kDigits) + " follows " + format_number(table.times[i - 1], kDigits));
  for (std::size_t i = 0; i < table.values.size(); ++i)
    if (!(table.values[i] >= 0) || !std::isfinite(table.values[i]))
      t.fail("values", t.path() + ".values[" + std::to_string(i) + "] = " + format_number(table.values[i], kDigits) +
                           " must be a finite number >= 0 (" + unit + ")");
  return table;
}

}  // namespace

FluidConfig read_fluid(const TableReader& r) {
  r.check_keys(kFluidKeys);
  FluidConfig f;
  f.viscosity = r.required_number("viscosity", kPositive);
  f.residual_aperture = r.required_number("residual_aperture", kPositive);
  f.max_aperture = r.required_number("max_aperture", kPositive);
  if (!(f.max_aperture > f.residual_aperture))
    r.fail("max_aperture", r.key_path("max_aperture") + " = " + format_number(f.max_aperture, kDigits) +
                               " must be larger than residual_aperture = " + format_number(f.residual_aperture, kDigits));
  f.safety = r.number("safety", Range{0.0, 1.0, true, false}).value_or(0.5);
  f.damaged_segments = r.choice<bool>("segments", {{"damaged", true}, {"broken", false}}).value_or(true);
  f.cap_aperture = r.choice<bool>("aperture_limit", {{"stop", false}, {"cap", true}}).value_or(false);
  if (auto crack = r.string("crack")) {
    check_region_name(r, "crack", *crack);
    f.crack = *crack;
  }
  if (const toml::table* t = subtable(r, "gas")) {
    // The gas's own state law and source (the hole) replace the liquid's keys.
    for (const char* key : {"bulk_modulus", "source", "rate", "pressure", "leak_off"})
      if (r.has(key))
        r.fail(key, r.key_path(key) + " is not allowed with [fluid.gas]: the gas's state law p = p0 (ρ/ρ0)^γ and its "
                                      "hole (fluid.gas.hole) take its place" +
                        (std::string(key) == "leak_off" ? std::string(" (no leak-off for the gas)") : std::string()));
    const TableReader g = subtable_reader(r, *t, "gas");
    g.check_keys(kGasKeys);
    GasConfig gas;
    gas.gamma = g.required_number("gamma", Range{1.0, 10.0, true, false});
    gas.density = g.required_number("density", kPositive);
    gas.pressure = g.required_number("pressure", kPositive);
    gas.hole = g.required_string("hole");
    check_region_name(g, "hole", gas.hole);
    f.gas = gas;
    return f;
  }
  f.bulk_modulus = r.required_number("bulk_modulus", kPositive);
  f.leak_off = r.number("leak_off", kNonNegative).value_or(0.0);
  f.source = r.required_string("source");
  check_region_name(r, "source", f.source);
  r.exactly_one("rate", "pressure");
  f.rate = number_or_table(r, "rate", kNonNegative, "m²/s");
  f.pressure = number_or_table(r, "pressure", kNonNegative, "Pa");
  return f;
}

}  // namespace fdem::io::detail
