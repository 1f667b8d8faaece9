// The flow network of [fluid] (engine/stages/fluid_flow.*): which CE4s carry fluid
// between which network vertices, where the fluid enters, and the fluid's stable step.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/case_config.hpp"

namespace fdem {

struct Model;

// A network vertex is a mesh vertex of the unsplit mesh where CE4s meet: every copy of it
// that the fracturable split made (Model::node_origin) is the same vertex, so the fluid
// at a crack's vertex is one pressure whatever the number of triangles around it. A
// segment is a CE4: it joins the vertices of its ends i (= i') and j (= j') and carries
// fluid while it is broken (CohesiveForces status ≥ 1) or, with damaged_segments, softened.
struct FluidModel {
  bool enabled = false;
  double viscosity = 0, bulk_modulus = 0, residual_aperture = 0, max_aperture = 0, safety = 0.5;
  bool damaged_segments = true;  // softened intact CE4s carry fluid too (fluid.segments = "damaged")
  double leak_off = 0;  // Carter's C_L [m/√s]: 2 C_L / √(t - t_exposed) per unit area of a segment
  std::vector<uint32_t> segment_vertex;  // 2 per CE4: its i and j ends' vertices
  std::vector<double> segment_length;    // per CE4: reference length h [m]
  size_t vertices = 0;
  // Vertex → segment ends, CSR in ascending (CE4, end): entry = 2 × CE4 + end (0: i, 1: j).
  std::vector<uint32_t> vertex_start, vertex_end;
  std::vector<int> vertex_mesh_node;     // per vertex: the mesh node (split model index) of its lowest copy
  std::vector<uint32_t> crack_ce4;       // CE4s on [fluid] crack: broken from the start
  std::vector<uint32_t> source_vertices; // ascending
  std::string source_name, crack_name;
  bool pressure_source = false;          // the source holds `history` [Pa], else injects `history` [m²/s]
  io::PressureTable history;
  bool cap_aperture = false;             // fluid.aperture_limit = "cap": conductance from min(w_m, w_max), no stop
  // [fluid.gas]: a polytropic gas p = p0 (V₀/V)^γ, V₀ its volume at the reference density
  // ρ0 (V₀ ρ0 is its mass), filling the blast hole at the start; the hole is the source:
  // its wall's network vertices are held at the hole's pressure, and the gas they take
  // leaves the hole (FluidFlow, cl_kernels/fluid_flow.cl gas_hole).
  bool gas = false;
  double gamma = 0, gas_density = 0, gas_pressure = 0;
  std::string hole_name;
  // The hole's wall as a closed polygon of split nodes, clockwise (the body on the left of
  // each wall edge): edge by edge a, b, next edge's a, ...; a crack's mouth is the step
  // from one edge's b to the next one's a (two copies of one mesh vertex, apart once open).
  std::vector<uint32_t> hole_polygon;
  double hole_volume = 0;                // at the start [m³] (area × thickness)
  // The modulus the stable step uses: K_f, or γ p0 for the gas (its K = γ p at p0).
  double stiffness() const { return gas ? gamma * gas_pressure : bulk_modulus; }
  // Stable step of the explicit flow, 3 μ h² / (K w_max²) for the shortest CE4 (h), K the
  // stiffness() above: the fluid stage sub-cycles at safety × it (FluidFlow::substeps).
  double stable_dt = 0;
  size_t shortest_ce4 = 0;
};

// The network of `model` (after the fracturable split) for `config`. Throws InputError
// (file, key) when the case has no CE4s, the crack or source region is missing or touches
// no CE4, or the source touches no crack segment at the start (the fluid would have no room).
FluidModel build_fluid_model(const Model& model, const io::FluidConfig& config, const std::string& case_path);

// The source's value at time t [s] (piecewise linear, held outside the table).
double fluid_source_value(const io::PressureTable& table, double t);

}  // namespace fdem
