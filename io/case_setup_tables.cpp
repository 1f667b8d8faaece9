// [mesh], [time], [output], [gravity], [damping], [in_situ]: how the run is set up.
#include "io/case_tables.hpp"

#include <cmath>

#include <filesystem>

namespace fdem::io::detail {
namespace {

namespace fs = std::filesystem;

std::string resolve_against(const std::string& dir, const std::string& file) {
  const fs::path p(file);
  if (p.is_absolute()) return file;
  return (fs::path(dir) / p).lexically_normal().string();
}

// The output files are output.dir / (name + a suffix): a name is one file name, so that
// nothing is written outside output.dir. "" when `name` is fine, else what is wrong.
std::string output_name_problem(const std::string& name) {
  if (name.empty()) return "must not be empty";
  if (name == "." || name == "..") return "is a directory, not a file name";
  if (name.find_first_of("/\\") != std::string::npos)
    return "holds a path separator: it is the base name of files inside output.dir (give directories "
           "in output.dir)";
  if (const std::string c = control_character(name); !c.empty())
    return "holds a control character (" + c + "): a name is one line of printable characters";
  if (name.size() > kMaxOutputName)
    return "is " + std::to_string(name.size()) + " bytes long, more than the limit of " +
           std::to_string(kMaxOutputName) + " (the files add suffixes such as _fragments.nc.resume, and a "
           "file name holds at most 255 bytes)";
  return "";
}

}  // namespace

void check_region_name(const TableReader& r, std::string_view key, const std::string& name) {
  if (name.size() > kMaxRegionName)
    r.fail(key, r.key_path(key) + ": region name " + quoted_text(name.substr(0, 40)) + "... is " +
                    std::to_string(name.size()) + " bytes long, more than the " + std::to_string(kMaxRegionName) +
                    " that history variable names leave for it (netCDF names hold 256 bytes)");
}

MeshConfig read_mesh(const TableReader& r, const std::string& case_dir) {
  r.check_keys(kMeshKeys);
  r.exactly_one("geo", "file");
  MeshConfig m;
  const std::string_view key = r.has("geo") ? "geo" : "file";
  const std::string resolved = resolve_against(case_dir, r.required_string(key));
  std::error_code ec;
  if (!fs::is_regular_file(resolved, ec))
    r.fail(key, r.key_path(key) + ": file not found: " + resolved);
  (key == "geo" ? m.geo : m.file) = resolved;
  if (r.has("size") && key == "file")
    r.fail("size", "mesh.size only applies with mesh.geo (gmsh meshes the .geo at that size)");
  m.size = r.number("size", kPositive).value_or(0.0);
  m.scale = r.number("scale", kPositive).value_or(1.0);
  m.thickness = r.number("thickness", kPositive).value_or(1.0);
  m.refine = r.integer<int>("refine", 0).value_or(0);
  if (r.has("algorithm") && key == "file")
    r.fail("algorithm", "mesh.algorithm only applies with mesh.geo (it is the algorithm gmsh meshes the .geo with)");
  m.algorithm = r.choice<std::string>("algorithm", {{"frontal-delaunay", "frontal-delaunay"},
                                                    {"delaunay", "delaunay"},
                                                    {"meshadapt", "meshadapt"}})
                    .value_or("");
  m.order = r.choice<std::string>("order", {{"hilbert", "hilbert"}, {"file", "file"}}).value_or("hilbert");
  if (const toml::table* t = subtable(r, "perturb")) {
    const TableReader perturb = subtable_reader(r, *t, "perturb");
    perturb.check_keys(kMeshPerturbKeys);
    if (!perturb.has("amplitude")) perturb.missing("amplitude");
    m.perturb = *perturb.number("amplitude", Range{0.0, 0.5, false, false});
    m.perturb_seed = perturb.integer<long>("seed", 0).value_or(1);
    m.perturb_min_quality = perturb.number("min_quality", Range{0.0, 1.0, false, false}).value_or(0.5);
  }
  return m;
}

TimeConfig read_time(const TableReader& r) {
  r.check_keys(kTimeKeys);
  TimeConfig t;
  if (!r.has("dt")) r.missing("dt");
  const std::optional<double> dt = *r.number_or_keyword("dt", "auto", kPositive);
  t.dt_auto = !dt;
  t.dt = dt.value_or(0.0);
  t.safety = r.number("safety", Range{0.0, 1.0, true, false}).value_or(0.5);
  r.exactly_one("end", "steps");
  t.end = r.number("end", kPositive).value_or(-1.0);
  t.steps = r.integer<long>("steps", 1).value_or(-1);
  return t;
}

OutputConfig read_output(const TableReader& r, const std::string& case_path) {
  r.check_keys(kOutputKeys);
  OutputConfig o;
  if (auto dir = r.string("dir")) o.dir = *dir;
  if (o.dir.empty()) r.fail("dir", "output.dir must not be empty");
  if (auto name = r.string("name")) {
    o.name = *name;
    if (const std::string problem = output_name_problem(o.name); !problem.empty())
      r.fail("name", "output.name = " + quoted_text(o.name) + " " + problem);
  } else {
    o.name = fs::path(case_path).stem().string();
    if (const std::string problem = output_name_problem(o.name); !problem.empty())
      r.ctx().fail(r.table(), "output.name is not given, and the case file's stem " + quoted_text(o.name) +
                                  ", its default, " + problem + ": give output.name");
  }
  r.exclusive("frames", "every");
  o.every = r.number("every", kPositive).value_or(-1.0);
  o.frames = r.integer<int>("frames", 1).value_or(o.every > 0 ? -1 : 20);
  o.history_every = r.number("history_every", kPositive).value_or(-1.0);
  if (r.has("regions")) o.regions = *r.strings("regions");
  for (const std::string& region : o.regions) check_region_name(r, "regions", region);
  o.energy_limit = r.number("energy_limit", kPositive).value_or(o.energy_limit);
  o.checkpoint_every = r.number("checkpoint_every", kNonNegative).value_or(0.0);
  o.float_frames = r.choice<bool>("precision", {{"double", false}, {"float", true}}).value_or(false);
  o.compress = r.boolean("compress").value_or(false);
  if (const toml::table* t = subtable(r, "events")) {
    const TableReader events = subtable_reader(r, *t, "events");
    events.check_keys(kOutputEventsKeys);
    o.events_distance = events.number("distance", kPositive).value_or(0.0);
    o.events_window = events.number("window", kPositive).value_or(0.0);
  }
  return o;
}

GravityConfig read_gravity(const TableReader& r) {
  r.check_keys(kGravityKeys);
  if (!r.has("g")) r.missing("g");
  return GravityConfig{*r.pair("g")};
}

DampingConfig read_damping(const TableReader& r) {
  r.check_keys(kDampingKeys);
  DampingConfig d;
  if (auto alpha = r.number("local", Range{0.0, 1.0, false, true})) {
    d.local_enabled = true;
    d.local = *alpha;
  }
  d.mass_scaling = r.boolean("mass_scaling").value_or(false);
  return d;
}

// The initial stress field. A uniform part, as components (`stress`) or as principal
// stresses and the angle of the first (`principal`, `angle`), and a part growing with depth
// below `datum` (σ_v = ρ g z; σ_H = k_H σ_v, σ_h = k_h σ_v at `azimuth` from x). What
// needs the mesh, the materials or gravity (tension on a CE4, a datum below the mesh, no
// gravity) is checked by the model (engine/model.cpp, check_in_situ).
InSituConfig read_in_situ(const TableReader& r) {
  r.check_keys(kInSituKeys);
  InSituConfig s;
  if (!r.has("stress") && !r.has("principal") && !r.has("datum"))
    r.ctx().fail(r.table(), "[in_situ] needs 'stress', 'principal' or 'datum' (a field that grows with depth)");
  r.exclusive("stress", "principal");
  if (r.has("stress")) {
    const std::vector<double> v = read_numbers(r, "stress");
    if (v.size() != 3)
      r.fail("stress", r.key_path("stress") + " must hold 3 numbers [sxx, syy, sxy] (Pa, tension positive), found " +
                           std::to_string(v.size()));
    s.stress = {v[0], v[1], v[2]};
  }
  if (r.has("angle") && !r.has("principal"))
    r.fail("angle", r.key_path("angle") + " is the direction of principal[0]: it needs 'principal'");
  if (auto p = r.pair("principal")) {
    const double a = r.number("angle").value_or(0.0) * std::acos(-1.0) / 180.0;
    const double c = std::cos(a), sn = std::sin(a);
    const double s1 = (*p)[0], s2 = (*p)[1];
    s.stress = {s1 * c * c + s2 * sn * sn, s1 * sn * sn + s2 * c * c, (s1 - s2) * sn * c};
  }
  for (const char* key : {"density", "k_H", "k_h", "azimuth"})
    if (r.has(key) && !r.has("datum"))
      r.fail(key, r.key_path(key) + " belongs to the part that grows with depth: it needs 'datum' (the y of the surface)");
  if (r.has("datum")) {
    s.datum = r.number("datum");
    s.density = r.number("density", kPositive);
    if (!r.has("k_H")) r.missing("k_H");
    s.k_H = r.required_number("k_H", kNonNegative);
    s.k_h = r.number("k_h", kNonNegative).value_or(s.k_H);
    s.azimuth = r.number("azimuth").value_or(0.0);
  }
  return s;
}

}  // namespace fdem::io::detail
