#include "io/case_schema.hpp"

#include "io/suggest.hpp"

namespace fdem::io::detail {
namespace {

// An [[interface]] has the keys of [material.fracture] and the pair of materials.
Schema with_fields(std::vector<Field> fields, const Schema& more) {
  fields.insert(fields.end(), more.fields.begin(), more.fields.end());
  return Schema{std::move(fields)};
}

// How a name is written in messages: top-level tables in brackets, keys in quotes.
std::string spelled(std::string_view name, Shape shape, bool top_level) {
  if (top_level && shape == Shape::Table) return "[" + std::string(name) + "]";
  if (top_level && shape == Shape::TableArray) return "[[" + std::string(name) + "]]";
  return "'" + std::string(name) + "'";
}

}  // namespace

// Defined in dependency order: a table's schema after the schemas of its sub-tables.
const Schema kMeshPerturbKeys{{{"amplitude"}, {"seed"}, {"min_quality"}}};
const Schema kMeshKeys{{{"geo"}, {"file"}, {"size"}, {"scale"}, {"thickness"}, {"refine"}, {"algorithm"}, {"order"},
                        {"perturb", Shape::Table, &kMeshPerturbKeys}}};
const Schema kTimeKeys{{{"dt"}, {"safety"}, {"end"}, {"steps"}}};
const Schema kOutputEventsKeys{{{"distance"}, {"window"}}};
const Schema kOutputKeys{{{"dir"}, {"name"}, {"frames"}, {"every"}, {"history_every"}, {"regions"},
                          {"energy_limit"}, {"checkpoint_every"}, {"precision"}, {"compress"},
                          {"events", Shape::Table, &kOutputEventsKeys}}};
const Schema kStiffnessKeys{
    {{"c11"}, {"c22"}, {"c12"}, {"c66"}, {"c16"}, {"c26"}, {"angle"}}};
const Schema kPenaltyKeys{{{"opening"}, {"sliding"}, {"overlap"}}};
const Schema kSofteningKeys{{{"a"}, {"b"}, {"c"}}};
const Schema kFractureKeys{{{"tensile_strength"}, {"cohesion"}, {"friction_angle"}, {"gf1"},
                            {"gf2"}, {"model"}, {"penalty", Shape::Table, &kPenaltyKeys},
                            {"softening", Shape::Table, &kSofteningKeys}}};
const Schema kHeterogeneityKeys{{{"homogeneity"}, {"seed"}, {"properties"}}};
const Schema kMaterialKeys{{{"name"}, {"regions"}, {"density"}, {"young"}, {"poisson"},
                            {"elasticity"}, {"plane"}, {"viscosity"},
                            {"stiffness", Shape::Table, &kStiffnessKeys},
                            {"fracture", Shape::Table, &kFractureKeys},
                            {"heterogeneity", Shape::Table, &kHeterogeneityKeys}}};
const Schema kInterfaceKeys = with_fields({{"materials"}}, kFractureKeys);
const Schema kJointSetKeys{{{"angle"}, {"kappa"}, {"spacing"}, {"trace_length"}, {"persistence"}, {"seed"}}};
const Schema kJointKeys = with_fields({{"name"}, {"curves"}, {"file"}, {"set", Shape::Table, &kJointSetKeys}, {"broken"}},
                                      kFractureKeys);
const Schema kGrainsKeys{{{"region"}, {"size"}, {"count"}, {"seed"}, {"minerals"}, {"fractions"},
                          {"boundary", Shape::Table, &kFractureKeys}}};
const Schema kGravityKeys{{{"g"}}};
const Schema kDampingKeys{{{"local"}, {"mass_scaling"}}};
const Schema kBlastKeys{{{"peak"}, {"rise"}, {"ratio"}}};
const Schema kPressureTableKeys{{{"times"}, {"values"}}};
const Schema kBoundaryKeys{{{"region"}, {"fix"}, {"velocity"}, {"rise"}, {"traction"}, {"pressure"},
                            {"blast", Shape::Table, &kBlastKeys}, {"absorbing"}, {"in_situ"}}};
const Schema kInitialKeys{{{"region"}, {"velocity"}}};
const Schema kContactDampingKeys{{{"transition"}, {"exponent"}}};
const Schema kContactPairKeys{{{"materials"}, {"normal_penalty"}, {"tangential_penalty"},
                               {"friction"}, {"damping", Shape::Table, &kContactDampingKeys}}};
const Schema kContactKeys{{{"normal_penalty"}, {"tangential_penalty"}, {"friction"},
                           {"damping", Shape::Table, &kContactDampingKeys}, {"activation"},
                           {"regions"}, {"rebuild"}, {"skin"}, {"joins"},
                           {"pair", Shape::TableArray, &kContactPairKeys}}};
const Schema kProbeKeys{{{"name"}, {"point"}}};
const Schema kInSituKeys{{{"stress"}, {"principal"}, {"angle"}, {"datum"}, {"density"}, {"k_H"}, {"k_h"},
                          {"azimuth"}}};
const Schema kExcavationKeys{{{"region"}, {"start"}, {"duration"}}};
const Schema kGasKeys{{{"gamma"}, {"density"}, {"pressure"}, {"hole"}}};
const Schema kFluidKeys{{{"viscosity"}, {"bulk_modulus"}, {"residual_aperture"}, {"max_aperture"}, {"safety"}, {"leak_off"}, {"segments"},
                         {"crack"}, {"source"}, {"rate"}, {"pressure"}, {"aperture_limit"},
                         {"gas", Shape::Table, &kGasKeys}}};
const Schema kRootKeys{{{"title"},
                        {"mesh", Shape::Table, &kMeshKeys},
                        {"time", Shape::Table, &kTimeKeys},
                        {"output", Shape::Table, &kOutputKeys},
                        {"material", Shape::TableArray, &kMaterialKeys},
                        {"interface", Shape::TableArray, &kInterfaceKeys},
                        {"joint", Shape::TableArray, &kJointKeys},
                        {"grains", Shape::Table, &kGrainsKeys},
                        {"gravity", Shape::Table, &kGravityKeys},
                        {"damping", Shape::Table, &kDampingKeys},
                        {"boundary", Shape::TableArray, &kBoundaryKeys},
                        {"initial", Shape::TableArray, &kInitialKeys},
                        {"contact", Shape::Table, &kContactKeys},
                        {"probe", Shape::TableArray, &kProbeKeys},
                        {"in_situ", Shape::Table, &kInSituKeys},
                        {"excavation", Shape::TableArray, &kExcavationKeys},
                        {"fluid", Shape::Table, &kFluidKeys}}};

std::string nearest_key(std::string_view name, const std::vector<std::string_view>& candidates) {
  return nearest_name(name, candidates, LetterCase::Ignored);
}

std::string unknown_name_message(std::string_view name, Shape found, const Schema& schema,
                                 const std::string& heading) {
  const bool top = heading.empty();
  std::string msg;
  if (top && found != Shape::Key)
    msg = "unknown table " + spelled(name, found, top);
  else
    msg = "unknown key '" + std::string(name) + "'" + (top ? "" : " in " + heading);
  std::vector<std::string_view> names;
  for (const Field& f : schema.fields) names.push_back(f.name);
  const std::string guess = nearest_key(name, names);
  if (!guess.empty())
    msg += " (did you mean " + spelled(guess, schema.find(guess)->shape, top) + "?)";
  return msg;
}

Shape shape_of(const toml::node& n) {
  if (n.is_table()) return Shape::Table;
  return n.is_array_of_tables() ? Shape::TableArray : Shape::Key;
}

}  // namespace fdem::io::detail
