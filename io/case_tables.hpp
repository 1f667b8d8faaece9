// One reader per table of the case file, each checking its keys against the schema
// (io/case_schema.hpp) and its values' ranges, and returning the table as a plain value
// of io/case_config.hpp. read_case (io/case_reader.cpp) calls them in order.
#pragma once
#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/case_config.hpp"
#include "io/case_toml.hpp"

namespace fdem::io::detail {

// The longest output.name, in bytes (docs/case-format.md, [output]).
constexpr std::size_t kMaxOutputName = 200;

// A region named by [[boundary]], [[initial]], output.regions or contact.regions gets
// history variables named after it (REGION_force_x, with "r_" before a leading digit:
// engine/outputs/history_table.cpp), and netCDF names hold at most 256 bytes (NC_MAX_NAME).
constexpr std::size_t kMaxRegionName = 246;
// Fails at `key` when `name` is longer than kMaxRegionName.
void check_region_name(const TableReader& r, std::string_view key, const std::string& name);

// io/case_setup_tables.cpp: the run set-up.
MeshConfig read_mesh(const TableReader& r, const std::string& case_dir);      // [mesh]
TimeConfig read_time(const TableReader& r);                                   // [time]
OutputConfig read_output(const TableReader& r, const std::string& case_path); // [output]
GravityConfig read_gravity(const TableReader& r);                             // [gravity]
DampingConfig read_damping(const TableReader& r);                             // [damping]
InSituConfig read_in_situ(const TableReader& r);                              // [in_situ]
// io/case_fluid_table.cpp
FluidConfig read_fluid(const TableReader& r);                                 // [fluid]

// io/case_material_tables.cpp: what the body is made of.
// A material name is an Exodus block name: at most 32 bytes (io/exodus_writer.cpp), and
// not the name of the CE4 block (engine/run/run.cpp).
constexpr std::size_t kMaxMaterialName = 32;
constexpr const char* kCohesiveBlockName = "cohesive";
std::vector<MaterialConfig> read_materials(const TableReader& top);  // [[material]]
std::vector<InterfaceConfig> read_interfaces(const TableReader& top,  // [[interface]]
                                             const std::vector<MaterialConfig>& materials);
// [[joint]]: `file` resolved against `case_dir`; `file` and `set` need mesh.geo.
std::vector<JointConfig> read_joints(const TableReader& top, const std::string& case_dir, const MeshConfig& mesh);
// The most grains [grains] makes (count, or the region's area over size).
constexpr long kMaxGrains = 5000;
// [grains]: minerals named among `materials`, each fracturable; needs mesh.geo.
GrainsConfig read_grains(const TableReader& r, const std::vector<MaterialConfig>& materials, const MeshConfig& mesh);
// `materials = ["rock", "steel"]` of a [[contact.pair]] or an [[interface]]: two names of
// [[material]] entries; a misspelt one gets a suggestion.
std::array<std::string, 2> material_names(const TableReader& r,
                                          const std::vector<MaterialConfig>& materials);
// Each unordered pair once: ("rock", "steel") and ("steel", "rock") are the same.
// `seen` maps the pairs so far to the entry that gave them ("contact.pair[0]").
using PairEntries = std::map<std::pair<std::string, std::string>, std::string>;
void check_new_pair(PairEntries& seen, const TableReader& entry,
                    const std::array<std::string, 2>& names);

// io/case_boundary_tables.cpp: one [[boundary]] or [[initial]] entry.
BoundaryConfig read_boundary(const TableReader& r);
InitialConfig read_initial(const TableReader& r);

// io/case_contact_table.cpp: [contact] with its [[contact.pair]] entries.
ContactConfig read_contact(const TableReader& r, const std::vector<MaterialConfig>& materials);

// io/case_excavation_table.cpp: [[excavation]] entries.
std::vector<ExcavationConfig> read_excavations(const TableReader& top);

// io/case_probe_table.cpp: [[probe]] entries.
std::vector<ProbeConfig> read_probes(const TableReader& top);

}  // namespace fdem::io::detail
