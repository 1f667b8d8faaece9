// The model: the mesh turned into what the solver needs, in SI units. Built once on the
// host from a Gmsh mesh and a case; the solver copies it to the device.
//
// Data model: nodes (reference coordinates), TRI3 triangles grouped in contiguous
// blocks by material (one Exodus element block each), boundary-condition groups per
// node, loaded boundary edges, named regions. Every node belongs to at least one
// triangle (unused mesh nodes are dropped). A fracturable region will later own its
// own nodes (three per triangle); everything below indexes nodes through the triangle
// and edge lists, so split nodes need no change here beyond the mesh splitting.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/model/cohesive_model.hpp"
#include "engine/model/fluid_model.hpp"
#include "engine/model/materials.hpp"
#include "engine/model/excavation.hpp"
#include "engine/model/in_situ.hpp"
#include "io/case_config.hpp"
#include "io/mesh.hpp"

namespace fdem {

// Prescribed motion of a node: mask bit 0 = vx prescribed, bit 1 = vy; velocity ramped
// from 0 over `rise` seconds.
struct BoundaryGroup {
  uint32_t mask = 0;
  double vx = 0, vy = 0, rise = 0;
  bool operator==(const BoundaryGroup& o) const {
    return mask == o.mask && vx == o.vx && vy == o.vy && rise == o.rise;
  }
};

// What a load does to its edges (the kinds of cl_kernels/boundary_loads.cl).
// The values are the kernels' LOAD_* (engine/model/layouts.hpp).
enum class LoadKind {
  Traction = layout::LOAD_TRACTION,
  Pressure = layout::LOAD_PRESSURE,
  Blast = layout::LOAD_BLAST,
  Table = layout::LOAD_TABLE,
  Absorbing = layout::LOAD_ABSORBING,
  InSitu = layout::LOAD_IN_SITU,  // the in-situ field's traction σ₀·n on the reference edge (Model::in_situ)
  Gas = layout::LOAD_GAS          // [fluid.gas]: the hole's gas pressure, from the fluid stage's gas_hole (device)
};

struct EdgeLoad {
  LoadKind kind = LoadKind::Traction;
  double tx = 0, ty = 0;     // Traction: [Pa] (dead load per reference length)
  double pressure = 0;       // Pressure: [Pa], positive pushes into the body (follower load); Blast: peak P₀
  double rise = 0;           // Traction, Pressure: ramp time [s]; Blast: rise time t₀ [s]
  double ratio = 0;          // Blast: β/α (> 1)
  std::vector<double> times, values;  // Table: pressure [Pa] against time [s], piecewise linear
  int material = -1;         // Absorbing: the material on the inside of the edges

  static EdgeLoad make(LoadKind kind, double tx, double ty, double pressure, double rise, double ratio = 0) {
    EdgeLoad l;
    l.kind = kind, l.tx = tx, l.ty = ty, l.pressure = pressure, l.rise = rise, l.ratio = ratio;
    return l;
  }
};

// Eq. 21 written as P(t) = scale (e^{-αt} - e^{-βt}): α and β from the rise time
// t₀ = ln(β/α)/(β - α) and the ratio β/α, scale = P₀ / (e^{-αt₀} - e^{-βt₀}).
struct BlastPulse {
  double alpha = 0, beta = 0, scale = 0;
};
BlastPulse blast_pulse(double peak, double rise, double ratio);

struct LoadedEdge {
  int a = 0, b = 0;  // node indices; the body lies on the left of a → b
  int load = 0;      // index into Model::loads
};

struct Region {
  std::string name;
  int dim = 0;              // 1 curve, 2 surface (0 point)
  std::vector<int> nodes;   // sorted node indices
  bool prescribed = false;  // a boundary entry prescribes its motion (fix or velocity)
};

// Contact between triangles (cl_kernels/contact_forces.cl). Properties per unordered
// material pair: rows of layout::CONTACT_PROPS reals (PAIR_*: P_n [Pa], P_tan [Pa/m],
// μ, T [Pa], b, damped 0/1), row index pair_index[m1 * n_materials + m2].
struct ContactModel {
  bool enabled = false;
  bool rebuild_skin = false;  // rebuild only when a node moved more than skin/2
  double skin = 0.0;          // [m]
  bool skin_from_mesh = false;  // `skin` not given or "auto": the first skin is default_skin(model)
  bool skin_auto = false;       // `skin` not given or "auto": picked at each detection (ContactSkin::choose)
  // activation "fractured" with rebuild "skin": detections list the couples of every
  // triangle, and a couple acts once both its triangles take part (ContactDetection's
  // list_inactive, contact_forces.cl's PRELISTED), so a join needs no new list.
  bool list_ahead = false;
  std::vector<double> pair_props;
  std::vector<uint32_t> pair_index;
  double max_normal_penalty = 0.0, max_tangential_penalty = 0.0;
};

struct Model {
  std::string mesh_path;
  double thickness = 1.0;

  std::vector<double> x, y;       // reference coordinates [m]
  std::vector<long> node_tags;    // Gmsh tag of each node
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise, grouped by material
  std::vector<int> triangle_material;
  std::vector<long> triangle_tags;             // Gmsh element tag of each triangle
  std::vector<MaterialConstants> materials;
  std::vector<size_t> block_start;             // triangles of material m: [block_start[m], block_start[m+1])

  std::vector<uint32_t> node_group;          // index into groups; 0 = free
  std::vector<BoundaryGroup> groups;         // groups[0] is the free node
  std::vector<LoadedEdge> loaded_edges;
  std::vector<EdgeLoad> loads;

  std::vector<double> vx0, vy0;   // initial velocity [m/s]
  std::vector<Region> regions;    // every boundary and initial-condition region of the case

  ContactModel contact;
  // Contact candidates at the start, one per triangle (1 = candidate); empty = every
  // triangle (activation "all"). With activation "fractured" the triangles of the listed
  // regions; triangles next to a CE4 join when it breaks.
  std::vector<uint32_t> contact_active;
  // One rank's share of a split model with contact (engine/parallel/partition.* local_model; all
  // empty or zero for a whole model): per triangle 1 where this rank owns it (detection
  // lists only the couples whose lower triangle it owns, so each couple is computed once),
  // per node 1 where it owns the node (the skin test reads only those), per CE4 1 where
  // it owns the CE4 (only those flag a join of contact candidates), and the whole
  // model's longest edge and largest |coordinate| (the fixed-point scale and the contact
  // round-off must be those of one rank).
  std::vector<char> triangle_owned, node_owned, ce4_owned;
  double whole_longest_edge = 0, whole_reach = 0;

  // Cohesive elements (fracturable regions own their nodes: three per triangle).
  std::vector<std::array<int, 4>> ce4;            // nodes (i, j, j', i')
  std::vector<std::array<int, 2>> ce4_triangles;  // the two triangles it joins
  std::vector<int> ce4_properties;                // index into fracture
  std::vector<FractureProperties> fracture;       // per fracturable material, then per interface
  std::vector<bool> triangle_fracturable;
  // [[joint]] (all empty without): per CE4 the joint it lies on (-1: none), and per joint
  // its name and whether it starts broken (its CE4s closed: friction only).
  std::vector<int> ce4_joint;
  std::vector<std::string> joint_names;
  std::vector<char> joint_broken;
  // [grains] (all empty without): per triangle its grain (-1: outside the grains' region),
  // per grain its mineral (a material index) and area [m²] (of its triangles), and per
  // CE4 1 on a grain boundary (two grains), 0 inside one grain, -1 not between two grains'
  // triangles. The grain-boundary CE4s take the properties fracture[grain_boundary_fracture].
  std::vector<int> triangle_grain;
  std::vector<int> grain_mineral;
  std::vector<double> grain_area;
  std::vector<int> ce4_grain_boundary;
  int grain_boundary_fracture = -1;
  // After the split (empty without CE4s): the mesh node each node is a copy of, and per
  // mesh node whether its whole fan is bonded (every triangle at it fracturable, every
  // interior edge at it a CE4): 1 bonded, 0 not. The triangles around a bonded mesh node
  // are held together by its CE4s; contact leaves their corner couples alone while all
  // those CE4s are intact (cl_kernels/contact_forces.cl).
  std::vector<int> node_origin;
  std::vector<int> vertex_bonded;

  std::array<double, 2> gravity{0, 0};
  // [in_situ]: the initial stress of every triangle (at its reference centroid) and of
  // every CE4 (at its Gauss points); not enabled without the table.
  InSituField in_situ;
  // [material.heterogeneity] (engine/heterogeneity.hpp; both empty when no material has
  // it): per triangle the factor on its material's elastic constants (1 for the other
  // materials' triangles), per CE4 the factors on T_s and c (1, 1 for the others).
  std::vector<double> young_factor;
  std::vector<std::array<double, 2>> ce4_strength_factor;
  // The triangles [first, first + count) that young_factor's device copy holds: from the
  // first to the last triangle of the materials with a varying E (count 0: none).
  size_t young_first() const;
  size_t young_count() const;
  // [[excavation]] (engine/model/excavation.hpp; both empty without any): per triangle
  // the index of the excavation that removes it (-1: none), and the excavations.
  std::vector<int> triangle_excavation;
  std::vector<Excavation> excavations;
  FluidModel fluid;  // [fluid]: the flow network on the cracks (engine/model/fluid_model.hpp)
  double local_damping = 0;  // Cundall α (0: none)
  bool mass_scaling = false;

  size_t num_nodes() const { return x.size(); }
  size_t num_triangles() const { return triangles.size(); }
};

// Builds the model from the mesh refined config.mesh.refine times (io::refine_mesh, right
// after the orientation check; 0 uses the mesh as read). Throws InputError naming the mesh file or case key for: a region
// name the mesh lacks (with a suggestion), a physical surface without a material, a
// surface in two materials, a load on a curve that is not on the boundary, conflicting
// prescribed velocities on one node. Notes (re-oriented triangles, dropped nodes) go to
// `notes`.
Model build_model(const io::Mesh& mesh, const io::CaseConfig& config, std::vector<std::string>& notes);

// The in-situ field of `model` (Model::in_situ) at each triangle's reference centroid,
// (σxx, σyy, σxy) [Pa]; empty when the model has none.
std::vector<std::array<double, 3>> in_situ_triangle_stress(const Model& model);
// The gaps each CE4 needs to carry it (in_situ_gaps); empty when the model has none.
// Throws InputError where a CE4 cannot (build_model refuses such a case first).
std::vector<InSituGaps> in_situ_ce4_gaps(const Model& model);

// What `fdem check` says of the in-situ field: the formula and its value at the top and
// the bottom of the mesh, and how many edges carry its traction; "" without one.
std::string in_situ_summary(const Model& model);

// What `fdem check` says of each heterogeneous material: its Weibull modulus and seed, and
// per varying property the range and mean of the factors drawn; empty without any.
std::vector<std::string> heterogeneity_summary(const Model& model, const io::CaseConfig& config);
// One line per [[joint]] for `fdem check`: its name, curves, CE4 count, total length and
// its properties (or "broken" with its friction angle).
std::vector<std::string> joint_summary(const Model& model, const io::CaseConfig& config);

// `fdem check`'s line on [grains]: the number of grains, their mean size (the diameter of
// a disc of their mean area), each mineral's share of the area (asked, achieved) and the
// grain-boundary CE4s; "" without grains.
std::string grains_summary(const Model& model, const io::CaseConfig& config);

// The mean edge length of the model's triangles [m] (every triangle, reference
// positions): the element size h of the contact defaults below.
double mean_edge_length(const Model& model);

// The contact skin when [contact] gives no `skin` and rebuilds by "skin" (the default):
// kDefaultSkinFraction × the mean edge length of the model's triangles [m]. A fifth of an
// element: candidates grow by about that much around each box, and the detection runs
// again once a node has moved a tenth of an element (docs/case-format.md).
constexpr double kDefaultSkinFraction = 0.2;
double default_skin(const Model& model);

// P_tan when neither [contact] nor the pair gives `tangential_penalty`: 6 P_n / h [Pa/m],
// h = mean_edge_length. Two triangles of size h overlapping by d over a length L push
// apart with about 6 P_n d L / h (the modulus stable_time_step uses), a normal stiffness
// of 6 P_n / h per unit length and thickness; the friction spring P_tan × L is then as
// stiff along the contact as across it, so an elastic slip before sliding is about as
// small as the overlap (cases/sliding/README.md: a block that must stick creeps 11 µm
// instead of 16 mm with P_tan = P_n Pa/m).
constexpr double kTangentialPenaltyFactor = 6.0;
double default_tangential_penalty(double normal_penalty, double mean_edge);

// Warnings about a case that runs but that the method's own consistency or the seed
// paper advises against, each naming its key (`fdem check` prints them): a contact
// P_tan more than 10× away from 6 P_n / h, and CE4 penalties below 10 E (Section 3.4 of
// the paper: penalties near E must not be used for dynamic fracture).
// The speed [m/s] the case's loads give nodes, at the scale of the particle speed of the
// stress waves they send (σ / (ρ c) at the lowest impedance), or a prescribed or initial
// speed: the largest. 0 when the case says nothing that moves (gravity alone).
double speed_scale(const Model& model, const io::CaseConfig& config);
// With dt > 0 also: a contact skin the nodes cross in fewer than 30 steps at speed_scale.
std::vector<std::string> model_warnings(const Model& model, const io::CaseConfig& config, double dt = 0);

// Stable time step estimate over all triangles (the smallest triangle height h over the
// P-wave speed, reduced by the viscous damping ratio ξ: Δt = h/c (√(1+ξ²) − ξ)), and the
// triangle that sets it.
struct StableStep {
  double dt = 0;
  size_t triangle = 0;
};
StableStep stable_time_step(const Model& model);

}  // namespace fdem
