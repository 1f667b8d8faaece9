// The case file's key schema: the known keys of every table, listed once. It serves both
// to reject unknown keys and tables with a "did you mean" suggestion and to walk --set
// paths. Adding a key is one entry in io/case_schema.cpp plus reading it in its table's
// reader (io/case_tables.hpp).
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

namespace fdem::io::detail {

enum class Shape { Key, Table, TableArray };

struct Schema;

struct Field {
  constexpr Field(std::string_view n, Shape s = Shape::Key, const Schema* c = nullptr)
      : name(n), shape(s), child(c) {}
  std::string_view name;
  Shape shape;
  const Schema* child;  // the keys of a Table or of each TableArray entry
};

struct Schema {
  std::vector<Field> fields;
  const Field* find(std::string_view name) const {
    for (const Field& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  }
};

extern const Schema kMeshPerturbKeys, kMeshKeys, kTimeKeys, kOutputEventsKeys, kOutputKeys, kStiffnessKeys, kPenaltyKeys,
    kSofteningKeys, kFractureKeys, kMaterialKeys, kInterfaceKeys, kJointSetKeys, kJointKeys, kGrainsKeys, kGravityKeys, kDampingKeys,
    kBlastKeys, kPressureTableKeys, kBoundaryKeys, kInitialKeys, kContactDampingKeys,
    kContactPairKeys, kContactKeys, kProbeKeys, kInSituKeys, kHeterogeneityKeys, kExcavationKeys, kGasKeys, kFluidKeys, kRootKeys;

// The nearest of `candidates` to a misspelt name (letter case ignored), or "" when none
// is close enough to be a plausible typo.
std::string nearest_key(std::string_view name, const std::vector<std::string_view>& candidates);

// "unknown key 'youngs' in [[material]] (did you mean 'young'?)"; at the top level a
// table is "unknown table [gravty]". `heading` is empty for the top level.
std::string unknown_name_message(std::string_view name, Shape found, const Schema& schema,
                                 const std::string& heading);

Shape shape_of(const toml::node& n);

}  // namespace fdem::io::detail
