// [[excavation]] entries: regions removed from the model at a time or over a time.
#include "io/case_tables.hpp"

namespace fdem::io::detail {

// [[excavation]]: the region must be a physical surface of the mesh (checked with the
// model: engine/model/excavation.cpp); one region is excavated once.
std::vector<ExcavationConfig> read_excavations(const TableReader& top) {
  std::map<std::string, std::string> seen;  // region -> entry that excavates it
  return read_entries(top, "excavation", "region", [&](const TableReader& r) {
    r.check_keys(kExcavationKeys);
    ExcavationConfig e;
    e.region = r.required_string("region");
    check_region_name(r, "region", e.region);
    if (auto [it, fresh] = seen.emplace(e.region, r.path()); !fresh)
      r.fail("region", r.key_path("region") + " = \"" + e.region + "\" is already excavated by " + it->second +
                           ": a region is removed once");
    e.start = r.number("start", kNonNegative).value_or(0.0);
    e.duration = r.number("duration", kNonNegative).value_or(0.0);
    return e;
  });
}

}  // namespace fdem::io::detail
