// [[material]] entries (with [material.stiffness] and [material.fracture]) and
// [[interface]] entries, which bond two fracturable materials.
#include "io/case_tables.hpp"

#include <algorithm>
#include <filesystem>

#include "engine/model/cohesive_model.hpp"

namespace fdem::io::detail {
namespace {

Stiffness read_stiffness(const TableReader& r) {
  r.check_keys(kStiffnessKeys);
  Stiffness s;
  s.c11 = r.required_number("c11", kPositive);
  s.c22 = r.required_number("c22", kPositive);
  s.c12 = r.required_number("c12");
  s.c66 = r.required_number("c66", kPositive);
  s.c16 = r.number("c16").value_or(0.0);
  s.c26 = r.number("c26").value_or(0.0);
  s.angle = r.number("angle").value_or(0.0);
  // Leading principal minors of [[c11 c12 c16] [c12 c22 c26] [c16 c26 c66]]: a matrix that
  // is not positive definite has zero or negative strain energy for some strain.
  const double minor2 = s.c11 * s.c22 - s.c12 * s.c12;
  const double det = s.c11 * (s.c22 * s.c66 - s.c26 * s.c26) -
                     s.c12 * (s.c12 * s.c66 - s.c26 * s.c16) +
                     s.c16 * (s.c12 * s.c26 - s.c22 * s.c16);
  if (minor2 <= 0 || det <= 0)
    r.ctx().fail(r.table(), r.path() + " is not positive definite (need c11*c22 > c12^2 and a "
                                "positive determinant including c16, c26, c66)");
  return s;
}

// The keys [material.fracture] and [[interface]] share (the CE4 law, Eqs. 4–14); the
// caller checks for unknown keys, since an [[interface]] has one more.
FractureConfig read_fracture_keys(const TableReader& r) {
  FractureConfig f;
  f.tensile_strength = r.required_number("tensile_strength", kPositive);
  f.cohesion = r.required_number("cohesion", kPositive);
  f.friction_angle = r.required_number("friction_angle", Range{0.0, 90.0, false, true});
  f.gf1 = r.required_number("gf1", kPositive);
  f.gf2 = r.required_number("gf2", kPositive);
  f.extrinsic = r.choice<bool>("model", {{"intrinsic", false}, {"extrinsic", true}}).value_or(false);
  if (!r.has("penalty")) r.missing("penalty");
  const TableReader penalty = subtable_reader(r, *subtable(r, "penalty"), "penalty");
  penalty.check_keys(kPenaltyKeys);
  f.penalty_opening = penalty.required_number("opening", kPositive);
  f.penalty_sliding = penalty.required_number("sliding", kPositive);
  f.penalty_overlap = penalty.required_number("overlap", kPositive);
  if (const toml::table* t = subtable(r, "softening")) {
    const TableReader softening = subtable_reader(r, *t, "softening");
    softening.check_keys(kSofteningKeys);
    f.softening_a = softening.number("a", kPositive).value_or(f.softening_a);
    f.softening_b = softening.number("b", kPositive).value_or(f.softening_b);
    f.softening_c = softening.number("c", kPositive).value_or(f.softening_c);
    // Eq. 10 divides by 1 - a - b and needs f(0) = 1 > f(1) = 0 in between.
    if (!(f.softening_a + f.softening_b > 1.0))
      softening.fail(softening.blamed("a", "b"),
                     softening.path() + ": a + b = " +
                         format_number(f.softening_a + f.softening_b, kDigits) +
                         " is out of range (allowed: a + b > 1)");
    if (const std::string problem = softening_curve_problem(f.softening_a, f.softening_b, f.softening_c);
        !problem.empty())
      softening.fail(softening.blamed(softening.blamed("a", "b"), "c"),
                     softening.path() + " = { a = " + format_number(f.softening_a, kDigits) +
                               ", b = " + format_number(f.softening_b, kDigits) + ", c = " +
                               format_number(f.softening_c, kDigits) + " } is not a softening curve the "
                               "CE4 law can use (Eq. 10: f falls from 1 at D = 0 to 0 at D = 1): " + problem);
  }
  return f;
}

// A material's name is its element block's name in the Exodus file (engine/run/run.cpp),
// where names are fixed arrays of 32 bytes (io/exodus_writer.cpp, kMaxNameLength), and
// the CE4 block of a fracturable case is named "cohesive". "" when the name fits.
std::string material_name_problem(const std::string& name) {
  if (const std::string c = control_character(name); !c.empty())
    return "holds a control character (" + c + "): a name is one line of printable characters";
  if (name.size() > kMaxMaterialName)
    return "is " + std::to_string(name.size()) + " bytes long, more than the " +
           std::to_string(kMaxMaterialName) + " that fit in an Exodus block name";
  if (name == kCohesiveBlockName)
    return "is reserved: the Exodus file names its block of cohesive elements (CE4s) \"" +
           std::string(kCohesiveBlockName) + "\"";
  return "";
}

// `minerals`: the names [grains] lists (as written); such a material may have no
// `regions` (its triangles are the grains it is drawn for).
MaterialConfig read_material(const TableReader& r, const std::vector<std::string>& minerals) {
  r.check_keys(kMaterialKeys);
  MaterialConfig m;
  m.name = r.required_string("name");
  if (const std::string problem = material_name_problem(m.name); !problem.empty())
    r.fail("name", r.key_path("name") + " = " + quoted_text(m.name) + " " + problem);
  if (r.has("regions")) m.regions = *r.strings("regions");
  else if (std::find(minerals.begin(), minerals.end(), m.name) == minerals.end())
    r.ctx().fail(r.table(), r.title() + " is missing required key 'regions'" +
                                (minerals.empty() ? "" : " (or name it in grains.minerals: a mineral's triangles are its grains)"));
  m.density = r.required_number("density", kPositive);
  m.young = r.required_number("young", kPositive);
  m.poisson = r.required_number("poisson", Range{-1.0, 0.5, true, true});
  m.elasticity = r.choice<Elasticity>("elasticity", {{"neo-hookean", Elasticity::NeoHookean},
                                                     {"hyperelastic", Elasticity::Hyperelastic}})
                     .value_or(Elasticity::NeoHookean);
  m.plane = r.choice<Plane>("plane", {{"strain", Plane::Strain}, {"stress", Plane::Stress}})
                .value_or(Plane::Strain);
  if (const toml::table* t = subtable(r, "stiffness")) {
    if (m.elasticity != Elasticity::Hyperelastic)
      r.fail("stiffness", r.key_path("stiffness") +
                              " is only allowed with elasticity = \"hyperelastic\"");
    m.stiffness = read_stiffness(subtable_reader(r, *t, "stiffness"));
  }
  if (const toml::table* t = subtable(r, "fracture")) {
    const std::string path = r.key_path("fracture");
    const TableReader fracture(r.ctx(), *t, path, path,
                               "[material.fracture] of " + r.path() + " ('" + m.name + "')");
    fracture.check_keys(kFractureKeys);
    m.fracture = read_fracture_keys(fracture);
  }
  if (auto v = r.number_or_keyword("viscosity", "critical", kNonNegative)) {
    m.viscosity_critical = !*v;
    m.viscosity = v->value_or(0.0);
  }
  if (const toml::table* t = subtable(r, "heterogeneity")) {
    const TableReader h = subtable_reader(r, *t, "heterogeneity");
    h.check_keys(kHeterogeneityKeys);
    HeterogeneityConfig c;
    c.homogeneity = h.required_number("homogeneity", kPositive);
    if (!h.has("seed")) h.missing("seed");
    c.seed = static_cast<std::uint64_t>(*h.integer<std::int64_t>("seed", 0));
    if (!h.has("properties")) h.missing("properties");
    const std::vector<std::string> names = *h.strings("properties");
    for (const std::string& name : names) {
      bool* flag = name == "young" ? &c.young : name == "tensile_strength" ? &c.tensile_strength
                                               : name == "cohesion"       ? &c.cohesion
                                                                          : nullptr;
      if (!flag) {
        const std::string guess = nearest_key(name, {"young", "tensile_strength", "cohesion"});
        h.fail("properties", h.key_path("properties") + " lists \"" + name +
                                 "\", not a property that can vary (allowed: \"young\", \"tensile_strength\", "
                                 "\"cohesion\")" + (guess.empty() ? "" : " (did you mean \"" + guess + "\"?)"));
      }
      if (*flag) h.fail("properties", h.key_path("properties") + " lists \"" + name + "\" twice");
      *flag = true;
      if (name != "young" && !m.fracture)
        h.fail("properties", h.key_path("properties") + " lists \"" + name + "\", a property of the CE4s: " +
                                 r.path() + " ('" + m.name + "') has no [material.fracture]");
    }
    m.heterogeneity = c;
  }
  return m;
}

InterfaceConfig read_interface(const TableReader& r,
                               const std::vector<MaterialConfig>& materials) {
  r.check_keys(kInterfaceKeys);
  InterfaceConfig i;
  i.materials = material_names(r, materials);
  if (i.materials[0] == i.materials[1])
    r.fail("materials", r.key_path("materials") + " names '" + i.materials[0] +
                            "' twice: an interface joins two different materials (within one "
                            "material its [material.fracture] applies)");
  for (std::size_t k = 0; k < 2; ++k) {
    const auto m = std::find_if(materials.begin(), materials.end(),
                                [&](const MaterialConfig& c) { return c.name == i.materials[k]; });
    if (!m->fracture)
      r.ctx().fail(*r.find("materials")->as_array()->get(k),
                   r.key_path("materials") + "[" + std::to_string(k) + "] = \"" +
                       i.materials[k] + "\" is a [[material]] without [material.fracture]: an "
                       "interface joins two fracturable materials");
  }
  i.fracture = read_fracture_keys(r);
  return i;
}

// A [[joint]]: its curves and either the CE4 law's keys (as [material.fracture]) or
// broken = true with only friction_angle and penalty (a broken joint has no strength).
JointConfig read_joint(const TableReader& r, std::size_t index, const std::string& case_dir, const MeshConfig& mesh) {
  r.check_keys(kJointKeys);
  JointConfig j;
  j.name = r.string("name").value_or("joint" + std::to_string(index));
  if (const std::string problem = material_name_problem(j.name); !problem.empty())
    r.fail("name", r.key_path("name") + " = " + quoted_text(j.name) + " " + problem);
  if (!r.has("curves") && !r.has("file") && !r.has("set"))
    r.ctx().fail(r.table(), r.path() + " needs at least one of 'curves' (physical curves of the mesh), 'file' (a "
                                       "file of polylines) and 'set' (a statistical joint set)");
  if (r.has("curves")) {
    j.curves = *r.strings("curves");
    if (j.curves.empty()) r.fail("curves", r.key_path("curves") + " is empty: name at least one physical curve");
  }
  for (const char* key : {"file", "set"})
    if (r.has(key) && mesh.geo.empty())
      r.fail(key, r.key_path(key) + " needs mesh.geo: the joints are embedded into the .geo that gmsh meshes (with "
                                    "mesh.file, draw them as physical curves of the mesh and list them in 'curves')");
  if (r.has("file")) {
    const std::filesystem::path file(r.required_string("file"));
    j.file = (file.is_absolute() ? file : (std::filesystem::path(case_dir) / file)).lexically_normal().string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(j.file, ec)) r.fail("file", r.key_path("file") + ": file not found: " + j.file);
  }
  if (const toml::table* t = subtable(r, "set")) {
    const TableReader set = subtable_reader(r, *t, "set");
    set.check_keys(kJointSetKeys);
    JointSetConfig c;
    c.angle = set.required_number("angle", Range{-360.0, 360.0, false, false});
    c.kappa = set.number("kappa", kNonNegative).value_or(0.0);
    c.spacing = set.required_number("spacing", kPositive);
    c.trace_length = set.required_number("trace_length", kPositive);
    c.persistence = set.number("persistence", Range{0.0, 1.0, true, false}).value_or(1.0);
    if (!set.has("seed")) set.missing("seed");
    c.seed = static_cast<std::uint64_t>(*set.integer<std::int64_t>("seed", 0));
    j.set = c;
  }
  j.broken = r.boolean("broken").value_or(false);
  if (!j.broken) {
    j.fracture = read_fracture_keys(r);
    return j;
  }
  for (const char* key : {"tensile_strength", "cohesion", "gf1", "gf2", "softening"})
    if (r.has(key))
      r.fail(key, r.key_path(key) + " is not allowed with broken = true: a broken joint has no strength, only "
                                    "friction (friction_angle) and the penalties of its closed faces");
  j.fracture.friction_angle = r.required_number("friction_angle", Range{0.0, 90.0, false, true});
  if (!r.has("penalty")) r.missing("penalty");
  const TableReader penalty = subtable_reader(r, *subtable(r, "penalty"), "penalty");
  penalty.check_keys(kPenaltyKeys);
  j.fracture.penalty_opening = penalty.required_number("opening", kPositive);
  j.fracture.penalty_sliding = penalty.required_number("sliding", kPositive);
  j.fracture.penalty_overlap = penalty.required_number("overlap", kPositive);
  // Unused by a closed CE4 (its state is frozen at f = 0; T_s and c cancel out of its
  // overlap and friction stiffnesses), but the parameter row divides by them.
  j.fracture.tensile_strength = j.fracture.cohesion = 1.0;
  j.fracture.gf1 = j.fracture.gf2 = 1.0;
  return j;
}

}  // namespace

std::vector<JointConfig> read_joints(const TableReader& top, const std::string& case_dir, const MeshConfig& mesh) {
  std::map<std::string, std::string> path_of_name, joint_of_curve;
  std::size_t index = 0;
  return read_entries(top, "joint", "", [&](const TableReader& r) {
    JointConfig j = read_joint(r, index++, case_dir, mesh);
    if (auto [it, fresh] = path_of_name.emplace(j.name, r.path()); !fresh)
      r.fail("name", r.key_path("name") + ": '" + j.name + "' is already the name of " + it->second);
    for (const std::string& curve : j.curves)
      if (auto [it, fresh] = joint_of_curve.emplace(curve, r.path()); !fresh)
        r.fail("curves", r.key_path("curves") + ": curve '" + curve + "' is already in " + it->second +
                             ": a curve belongs to one joint");
    return j;
  });
}

std::vector<MaterialConfig> read_materials(const TableReader& top) {
  std::map<std::string, std::string> path_of_name;    // "rock" → "material[0]"
  std::map<std::string, std::string> owner_of_region;  // region → "material[0] ('rock')"
  // [grains] minerals (read properly by read_grains): materials that need no regions.
  std::vector<std::string> minerals;
  if (const toml::table* grains = top.table().get_as<toml::table>("grains"))
    if (const toml::array* names = grains->get_as<toml::array>("minerals"))
      for (const toml::node& n : *names)
        if (auto name = n.value_exact<std::string>()) minerals.push_back(*name);
  auto materials = read_entries(top, "material", "name", [&](const TableReader& r) {
    MaterialConfig m = read_material(r, minerals);
    if (auto [it, fresh] = path_of_name.emplace(m.name, r.path()); !fresh)
      r.fail("name", r.key_path("name") + ": '" + m.name + "' is already the name of " +
                         it->second);
    for (const std::string& region : m.regions)
      if (auto [it, fresh] = owner_of_region.emplace(region, r.path() + " ('" + m.name + "')");
          !fresh)
        r.fail("regions", r.key_path("regions") + ": region '" + region + "' is already in " +
                              it->second + ": a region belongs to one material");
    return m;
  });
  if (materials.empty()) top.ctx().fail(top.table(), "the case needs at least one [[material]]");
  return materials;
}

std::vector<InterfaceConfig> read_interfaces(const TableReader& top,
                                             const std::vector<MaterialConfig>& materials) {
  PairEntries seen;
  return read_entries(top, "interface", "", [&](const TableReader& entry) {
    InterfaceConfig i = read_interface(entry, materials);
    check_new_pair(seen, entry, i.materials);
    return i;
  });
}

GrainsConfig read_grains(const TableReader& r, const std::vector<MaterialConfig>& materials, const MeshConfig& mesh) {
  r.check_keys(kGrainsKeys);
  GrainsConfig g;
  g.region = r.required_string("region");
  if (mesh.geo.empty())
    r.fail("region", r.path() + " needs mesh.geo: the grain boundaries are embedded into the .geo that gmsh meshes "
                                "(so that element edges follow them); mesh.file cannot take them");
  r.exactly_one("size", "count");
  g.size = r.number("size", kPositive).value_or(0.0);
  if (r.has("count")) {
    g.count = *r.integer<long>("count", 1);
    if (g.count > kMaxGrains)
      r.fail("count", r.key_path("count") + " = " + std::to_string(g.count) + " is out of range (allowed: " +
                          r.key_path("count") + " <= " + std::to_string(kMaxGrains) + ")");
  }
  if (!r.has("seed")) r.missing("seed");
  g.seed = static_cast<std::uint64_t>(*r.integer<std::int64_t>("seed", 0));
  if (!r.has("minerals")) r.missing("minerals");
  g.minerals = *r.strings("minerals");
  std::vector<std::string_view> known;
  for (const MaterialConfig& m : materials) known.push_back(m.name);
  const toml::array& names = *r.find("minerals")->as_array();
  for (std::size_t i = 0; i < g.minerals.size(); ++i) {
    const std::string path = r.key_path("minerals") + "[" + std::to_string(i) + "]";
    const auto m = std::find_if(materials.begin(), materials.end(),
                                [&](const MaterialConfig& c) { return c.name == g.minerals[i]; });
    if (m == materials.end()) {
      const std::string guess = nearest_key(g.minerals[i], known);
      r.ctx().fail(*names.get(i), path + " = \"" + g.minerals[i] + "\" is not the name of a [[material]]" +
                                      (guess.empty() ? "" : " (did you mean \"" + guess + "\"?)"));
    }
    if (!m->fracture)
      r.ctx().fail(*names.get(i), path + " = \"" + g.minerals[i] + "\" is a [[material]] without [material.fracture]: "
                                         "grains are fracturable (their CE4s take the mineral's fracture keys)");
    for (std::size_t k = 0; k < i; ++k)
      if (g.minerals[k] == g.minerals[i])
        r.ctx().fail(*names.get(i), path + " = \"" + g.minerals[i] + "\" is listed twice");
    if (!m->regions.empty())
      r.ctx().fail(*names.get(i), path + " = \"" + g.minerals[i] + "\" has regions of its own (" + m->regions[0] +
                                      "): a mineral's triangles are its grains; leave its regions out");
  }
  if (!r.has("fractions")) r.missing("fractions");
  const toml::node& fractions = *r.find("fractions");
  const toml::array* a = fractions.as_array();
  if (!a || a->size() != g.minerals.size())
    r.fail("fractions", r.key_path("fractions") + " must be an array of " + std::to_string(g.minerals.size()) +
                            " numbers (one per mineral), found " + describe(fractions));
  double sum = 0;
  for (std::size_t i = 0; i < a->size(); ++i) {
    g.fractions.push_back(as_number(r.ctx(), *a->get(i), r.key_path("fractions") + "[" + std::to_string(i) + "]",
                                    Range{0.0, 1.0, true, false}));
    sum += g.fractions.back();
  }
  if (std::fabs(sum - 1.0) > 1e-6)
    r.fail("fractions", r.key_path("fractions") + " sum to " + format_number(sum, kDigits) +
                            ", not 1 (area fractions of the minerals)");
  if (!r.has("boundary")) r.missing("boundary");
  const TableReader boundary = subtable_reader(r, *subtable(r, "boundary"), "boundary");
  boundary.check_keys(kFractureKeys);
  g.boundary = read_fracture_keys(boundary);
  return g;
}

std::array<std::string, 2> material_names(const TableReader& r,
                                          const std::vector<MaterialConfig>& materials) {
  std::array<std::string, 2> out;
  if (!r.has("materials")) r.missing("materials");
  const toml::node& names = *r.find("materials");
  const toml::array* a = names.as_array();
  if (!a || a->size() != 2)
    r.fail("materials", r.key_path("materials") +
                            " must be an array of 2 material names, found " + describe(names));
  std::vector<std::string_view> known;
  for (const MaterialConfig& m : materials) known.push_back(m.name);
  for (std::size_t i = 0; i < 2; ++i) {
    const toml::node& n = *a->get(i);
    const std::string path = r.key_path("materials") + "[" + std::to_string(i) + "]";
    out[i] = as_string(r.ctx(), n, path);
    if (std::find(known.begin(), known.end(), out[i]) != known.end()) continue;
    std::string msg = path + " = \"" + out[i] + "\" is not the name of a [[material]]";
    const std::string guess = nearest_key(out[i], known);
    if (!guess.empty()) msg += " (did you mean \"" + guess + "\"?)";
    r.ctx().fail(n, msg);
  }
  return out;
}

void check_new_pair(PairEntries& seen, const TableReader& entry,
                    const std::array<std::string, 2>& names) {
  const auto key = std::minmax(names[0], names[1]);
  if (auto [it, fresh] = seen.emplace(key, entry.path()); !fresh)
    entry.fail("materials", entry.key_path("materials") + ": the pair ('" + key.first +
                                "', '" + key.second + "') is already given in " + it->second);
}

}  // namespace fdem::io::detail
