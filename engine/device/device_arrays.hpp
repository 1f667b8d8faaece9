// Named device arrays (SoA: one real2 array per nodal quantity). Allocated and filled
// once from the Model; data stays on the device between steps.
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "engine/device/cl_context.hpp"
#include "engine/device/memory_plan.hpp"
#include "engine/model/model.hpp"
#include "engine/model/real.hpp"

namespace fdem {

struct DeviceArrays {
  size_t num_nodes = 0, num_triangles = 0, num_loaded_edges = 0;
  bool mass_scaling = false;  // node_mass holds (mass, inertia); else the mass alone

  // Nodes
  compute::buffer position;      // real2 [m], current
  compute::buffer velocity;      // real2 [m/s]
  compute::buffer ref_position;  // real2 [m], reference; only in a model with gravity (the
                                 // energy rows' gravity potential), else none (a null buffer)
  compute::buffer node_force;    // real2 [N]: gathered element and load forces, then (after
                                 // integrate) the out-of-balance force incl. gravity
  compute::buffer node_mass;     // real2 with mass scaling: (lumped mass [kg], inertia used by the
                                 // integrator [kg]); real without: the lumped mass (= inertia)
  compute::buffer node_group;    // uint: prescribed-motion group, 0 = free
  compute::buffer group_table;   // real4 per group: (mask, vx, vy, rise)

  // Triangles
  compute::buffer tri_nodes;     // uint ×3
  compute::buffer ref_inverse;   // real4: inverse reference edge matrix, row-major
  compute::buffer tri_material;  // uint
  compute::buffer materials;     // real, MATERIAL_STRIDE per material
  // [material.heterogeneity] on E only (else none allocated, young_count 0): the factor on
  // E of triangles [young_first, young_first + young_count) (Model::young_factor).
  compute::buffer young_factor;  // real
  size_t young_first = 0, young_count = 0;
  compute::buffer corner_force;  // real2 ×3 per triangle [N] (also the corner masses at set-up)
  compute::buffer stress;        // real4: σxx, σyy, σxy [Pa], J; output only: allocated by
                                 // output_stress(), null between output steps
  // The node → slot CSR map of the gather (cl_kernels/node_gather.cl): per node its
  // corner slots (3t+k), then its loaded-edge-end slots (2e+k), then its CE4 slots (4c+k),
  // each entry (part << 30) | slot, part 0, 1, 2 (node_slot_map).
  compute::buffer node_start;    // uint, num_nodes+1
  compute::buffer node_slot;     // uint, 3 per triangle + 2 per loaded edge + 4 per CE4

  // Loaded boundary edges
  compute::buffer edge_nodes;    // uint2 (a, b), body on the left
  compute::buffer edge_ref_position;  // real2 ×2 per edge: the reference positions of a, b
  compute::buffer edge_load;     // uint: index into load_table
  compute::buffer load_table;    // real4 per load: (kind, three parameters), see boundary_loads.cl
  compute::buffer pressure_points;  // real2 (time, pressure) of every pressure table, one after another
  compute::buffer edge_force;    // real2 ×2 per edge [N]


  // Contact
  compute::buffer contact_acc;   // long ×2 per node: contact force in fixed point (see ContactForces)

  compute::buffer conditions;    // int, CONDITION_WORDS: first offenders (INT_MAX = none)

  // Allocates the arrays of plan(model) and uploads the model.
  DeviceArrays(ClContext& cl, const Model& model);

  // The arrays above for `model`, by name and size (Solver::plan adds the stages').
  static MemoryPlan plan(const Model& model);
  // Whether the model has gravity (then ref_position is on the device).
  static bool has_gravity(const Model& model);
  // The reference positions as the device holds positions (real2 per node).
  static std::vector<real2> reference_positions(const Model& model);

  // `stress`, allocated when it is not (the stress evaluation of an output step);
  // release_output() gives it back once the step's output has read it.
  compute::buffer& output_stress(ClContext& cl);
  void release_output() { stress = compute::buffer(); }

 private:
  size_t stress_bytes_ = 0;
};

// Page-locked host memory for reads that must not wait: a buffer allocated with
// CL_MEM_ALLOC_HOST_PTR and kept mapped for its lifetime. NVIDIA's driver carries out a
// "non-blocking" read into ordinary (pageable) memory before returning, which drains the
// queue; into this memory the read is a real asynchronous copy. The monitor ring's reads
// (ContactSkin) land here. Zero-filled at construction.
template <typename T>
class PinnedHost {
 public:
  PinnedHost(ClContext& cl, size_t count) : queue_(cl.queue()), count_(count) {
    const size_t bytes = std::max<size_t>(1, count) * sizeof(T);
    try {
      buffer_ = compute::buffer(cl.context(), bytes, CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR);
      data_ = static_cast<T*>(queue_.enqueue_map_buffer(buffer_, CL_MAP_READ | CL_MAP_WRITE, 0, bytes));
    } catch (const compute::opencl_error& e) {
      throw DeviceError("cannot allocate " + std::to_string(bytes) + " bytes of page-locked host memory: " + e.what());
    }
    std::fill(data_, data_ + count_, T{});
  }
  ~PinnedHost() {
    if (data_) clEnqueueUnmapMemObject(queue_.get(), buffer_.get(), data_, 0, nullptr, nullptr);
  }
  PinnedHost(const PinnedHost&) = delete;
  PinnedHost& operator=(const PinnedHost&) = delete;
  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return count_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }

 private:
  compute::command_queue queue_;
  compute::buffer buffer_;
  size_t count_;
  T* data_ = nullptr;
};

// Host ↔ device copies that wait (only for set-up, output, history and checks).
template <typename T>
void upload(ClContext& cl, compute::buffer& buffer, const std::vector<T>& data) {
  if (!data.empty()) cl.queue().enqueue_write_buffer(buffer, 0, data.size() * sizeof(T), data.data());
}
template <typename T>
std::vector<T> download(ClContext& cl, const compute::buffer& buffer, size_t count, size_t first = 0) {
  std::vector<T> data(count);
  if (count) cl.queue().enqueue_read_buffer(buffer, first * sizeof(T), count * sizeof(T), data.data());
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

// The gather's one map (DeviceArrays::node_start, node_slot) from the three: per node its
// corner entries, then its edge entries, then its CE4 entries, each tagged with its part
// in the top two bits. InputError when a slot does not fit in 30 bits.
SlotMap node_slot_map(const SlotMap& corners, const SlotMap& edges, const SlotMap& ce4);

}  // namespace fdem
