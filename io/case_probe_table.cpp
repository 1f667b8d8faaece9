// [[probe]] entries: history points.
#include "io/case_tables.hpp"

#include <algorithm>
#include <cctype>

namespace fdem::io::detail {

constexpr std::size_t kMaxProbeName = 252;  // NC_MAX_NAME (256) less "_sxx"

// [[probe]] entries: the name prefixes history variables, so it must be a netCDF-safe
// identifier and unique. Whether the point lies in the mesh is checked with the model.
std::vector<ProbeConfig> read_probes(const TableReader& top) {
  std::map<std::string, std::string> seen;  // name -> entry that gave it
  return read_entries(top, "probe", "name", [&](const TableReader& r) {
    r.check_keys(kProbeKeys);
    ProbeConfig p;
    p.name = r.required_string("name");
    const bool identifier = std::isalpha(static_cast<unsigned char>(p.name[0])) &&
                            std::all_of(p.name.begin(), p.name.end(), [](char c) {
                              return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
                            });
    if (!identifier)
      r.fail("name", r.key_path("name") + " = \"" + p.name + "\" must start with a letter and "
                     "hold only letters, digits and '_' (it prefixes history variables)");
    // The history variables are NAME_vx ... NAME_sxy, and netCDF names hold 256 bytes.
    if (p.name.size() > kMaxProbeName)
      r.fail("name", r.key_path("name") + " is " + std::to_string(p.name.size()) + " characters long, more than the " +
                         std::to_string(kMaxProbeName) + " that its history variables (NAME_sxx) leave for it");
    if (auto [it, fresh] = seen.emplace(p.name, r.path()); !fresh)
      r.fail("name", r.key_path("name") + " = \"" + p.name + "\" is already the name of " +
                         it->second + ": probe names must be unique");
    if (!r.has("point")) r.missing("point");
    p.point = *r.pair("point");
    return p;
  });
}

}  // namespace fdem::io::detail
