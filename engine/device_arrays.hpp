// Named device arrays (SoA: one real2 array per nodal quantity). Allocated and filled
// once from the Model; data stays on the device between steps.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/cl_context.hpp"
#include "engine/memory_plan.hpp"
#include "engine/model.hpp"
#include "engine/real.hpp"

namespace fdem {

struct DeviceArrays {
  size_t num_nodes = 0, num_triangles = 0, num_loaded_edges = 0;

  // Nodes
  compute::buffer position;      // real2 [m], current
  compute::buffer velocity;      // real2 [m/s]
  compute::buffer ref_position;  // real2 [m], reference
  compute::buffer node_force;    // real2 [N]: gathered element and load forces, then (after
                                 // integrate) the out-of-balance force incl. gravity
  compute::buffer node_mass;     // real2: (lumped mass [kg], inertia used by the integrator [kg])
  compute::buffer node_group;    // uint: prescribed-motion group, 0 = free
  compute::buffer group_table;   // real4 per group: (mask, vx, vy, rise)

  // Triangles
  compute::buffer tri_nodes;     // uint ×3
  compute::buffer ref_inverse;   // real4: inverse reference edge matrix, row-major
  compute::buffer tri_material;  // uint
  compute::buffer materials;     // real, MATERIAL_STRIDE per material
  compute::buffer corner_force;  // real2 ×3 per triangle [N] (also the corner masses at set-up)
  compute::buffer stress;        // real4: σxx, σyy, σxy [Pa], J; output only: allocated by
                                 // output_stress(), null between output steps
  compute::buffer corner_start;  // uint, num_nodes+1: node → corner-slot CSR offsets
  compute::buffer corner_slot;   // uint, 3 per triangle: slot 3t+k of each node's corners

  // Loaded boundary edges
  compute::buffer edge_nodes;    // uint2 (a, b), body on the left
  compute::buffer edge_load;     // uint: index into load_table
  compute::buffer load_table;    // real4 per load: (kind, three parameters), see boundary_loads.cl
  compute::buffer pressure_points;  // real2 (time, pressure) of every pressure table, one after another
  compute::buffer edge_force;    // real2 ×2 per edge [N]
  compute::buffer edge_start;    // uint, num_nodes+1: node → edge-end-slot CSR offsets
  compute::buffer edge_slot;     // uint, 2 per edge

  // Cohesive elements: node → CE4-slot CSR map (the slots belong to CohesiveForces)
  compute::buffer ce4_start;     // uint, num_nodes+1
  compute::buffer ce4_slot;      // uint, 4 per CE4

  // Contact
  compute::buffer contact_acc;   // long ×2 per node: contact force in fixed point (see ContactForces)

  compute::buffer conditions;    // int, CONDITION_WORDS: first offenders (INT_MAX = none)

  // Allocates the arrays of plan(model) and uploads the model.
  DeviceArrays(ClContext& cl, const Model& model);

  // The arrays above for `model`, by name and size (Solver::plan adds the stages').
  static MemoryPlan plan(const Model& model);

  // `stress`, allocated when it is not (the stress evaluation of an output step);
  // release_output() gives it back once the step's output has read it.
  compute::buffer& output_stress(ClContext& cl);
  void release_output() { stress = compute::buffer(); }

 private:
  size_t stress_bytes_ = 0;
};

// Host ↔ device copies that wait (only for set-up, output, history and checks).
template <typename T>
void upload(ClContext& cl, compute::buffer& buffer, const std::vector<T>& data) {
  if (!data.empty()) cl.queue().enqueue_write_buffer(buffer, 0, data.size() * sizeof(T), data.data());
}
template <typename T>
std::vector<T> download(ClContext& cl, const compute::buffer& buffer, size_t count) {
  std::vector<T> data(count);
  if (count) cl.queue().enqueue_read_buffer(buffer, 0, count * sizeof(T), data.data());
  return data;
}

// node → slot CSR map: for each node, the slots (per_item × item + k) in which items
// (triangles, edges) hold its contributions, in increasing slot order.
struct SlotMap {
  std::vector<uint32_t> start, slot;
};
template <size_t N>
SlotMap build_slot_map(size_t num_nodes, const std::vector<std::array<int, N>>& items) {
  SlotMap map;
  map.start.assign(num_nodes + 1, 0);
  for (const auto& item : items)
    for (int n : item) map.start[n + 1]++;
  for (size_t i = 0; i < num_nodes; ++i) map.start[i + 1] += map.start[i];
  map.slot.resize(map.start[num_nodes]);
  std::vector<uint32_t> fill(map.start.begin(), map.start.end() - 1);
  for (size_t e = 0; e < items.size(); ++e)
    for (size_t k = 0; k < N; ++k) map.slot[fill[items[e][k]]++] = static_cast<uint32_t>(N * e + k);
  return map;
}

}  // namespace fdem
