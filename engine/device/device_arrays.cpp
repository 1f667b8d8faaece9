#include "engine/device/device_arrays.hpp"

#include <algorithm>
#include <climits>

#include "base/errors.hpp"

namespace fdem {

namespace {

// The (time, pressure) points of every pressure table, one after another; one dummy
// point when there are none.
// Rows of the load table: one per load, two for an in-situ traction (the field's datum
// row follows its kind row: boundary_loads.cl).
size_t load_rows(const Model& model) {
  size_t rows = 0;
  for (const auto& l : model.loads) rows += l.kind == LoadKind::InSitu ? 2 : 1;
  return rows;
}

size_t pressure_point_count(const Model& model) {
  size_t points = 0;
  for (const auto& l : model.loads)
    if (l.kind == LoadKind::Table) points += l.times.size();
  return std::max<size_t>(points, 1);
}

}  // namespace

bool DeviceArrays::has_gravity(const Model& model) { return model.gravity[0] != 0.0 || model.gravity[1] != 0.0; }

std::vector<real2> DeviceArrays::reference_positions(const Model& model) {
  std::vector<real2> pos(model.num_nodes());
  for (size_t i = 0; i < pos.size(); ++i) pos[i] = {real(model.x[i]), real(model.y[i])};
  return pos;
}

SlotMap node_slot_map(const SlotMap& corners, const SlotMap& edges, const SlotMap& ce4) {
  const size_t nodes = corners.start.size() - 1;
  constexpr uint32_t kSlotBits = 30;
  for (const SlotMap* m : {&corners, &edges, &ce4})
    if (!m->slot.empty() && *std::max_element(m->slot.begin(), m->slot.end()) >= (uint32_t(1) << kSlotBits))
      throw InputError("the model has more than 2^30 corner, loaded-edge or CE4 slots; the node gather's map indexes "
                       "them with 30 bits");
  const size_t total = corners.slot.size() + edges.slot.size() + ce4.slot.size();
  if (total > UINT32_MAX)
    throw InputError("the model has " + std::to_string(total) + " gather entries (3 per triangle, 2 per loaded edge, 4 per "
                     "CE4); the node gather's map counts them with 32 bits");
  SlotMap map;
  map.start.assign(nodes + 1, 0);
  map.slot.reserve(corners.slot.size() + edges.slot.size() + ce4.slot.size());
  for (size_t i = 0; i < nodes; ++i) {
    map.start[i] = static_cast<uint32_t>(map.slot.size());
    uint32_t part = 0;
    for (const SlotMap* m : {&corners, &edges, &ce4}) {
      if (m->start.size() == nodes + 1)
        for (uint32_t k = m->start[i]; k < m->start[i + 1]; ++k) map.slot.push_back(m->slot[k] | (part << kSlotBits));
      ++part;
    }
  }
  map.start[nodes] = static_cast<uint32_t>(map.slot.size());
  return map;
}

MemoryPlan DeviceArrays::plan(const Model& model) {
  const size_t n = model.num_nodes(), t = model.num_triangles(), e = model.loaded_edges.size();
  const size_t u = sizeof(uint32_t);
  MemoryPlan p;
  p.add("position", n * sizeof(real2)).add("velocity", n * sizeof(real2));
  // The reference positions: on the device only for the gravity potential of the energy
  // rows; the set-up (LumpedMass, CohesiveForces) takes them from the host
  // (reference_positions), the loads their edges' own (edge_ref_position).
  if (has_gravity(model)) p.add("ref_position", n * sizeof(real2));
  p
      .add("node_force", n * sizeof(real2))
      // (mass, inertia) with mass scaling; the mass alone without (LumpedMass)
      .add("node_mass", n * (model.mass_scaling ? sizeof(real2) : sizeof(real)))
      .add("node_group", n * u)
      .add("group_table", model.groups.size() * sizeof(real4))
      .add("tri_nodes", 3 * t * u)
      .add("ref_inverse", t * sizeof(real4))
      .add("tri_material", t * u)
      .add("materials", model.materials.size() * layout::MATERIAL_STRIDE * sizeof(real))
      .add("corner_force", 3 * t * sizeof(real2))
      .add("stress", t * sizeof(real4), MemoryPlan::Lifetime::Output)
      .add("node_start", (n + 1) * u)
      .add("node_slot", std::max<size_t>(1, 3 * t + 2 * e + 4 * model.ce4.size()) * u)
      .add("edge_nodes", 2 * e * u)
      .add("edge_ref_position", 2 * e * sizeof(real2))
      .add("edge_load", e * u)
      .add("load_table", std::max<size_t>(1, load_rows(model)) * sizeof(real4))
      .add("pressure_points", pressure_point_count(model) * sizeof(real2))
      .add("edge_force", 2 * e * sizeof(real2))
      .add("contact_acc", (model.contact.enabled ? n : 1) * 2 * sizeof(cl_long))
      .add("conditions", layout::CONDITION_WORDS * sizeof(int));
  // A varying E: one factor per triangle of the materials that vary it.
  if (model.young_count() > 0) p.add("young_factor", model.young_count() * sizeof(real));
  return p;
}

compute::buffer& DeviceArrays::output_stress(ClContext& cl) {
  if (stress.get() == nullptr) {
    stress = cl.allocate(stress_bytes_, "stress");
    // A triangle the stress pass finds inverted or not finite writes nothing: it reads 0,
    // not what the new array happened to hold (a failed run's last frame; every rank of a
    // split run the same). Before the array was transient it kept the last output's value.
    const real zero = 0;
    cl.queue().enqueue_fill_buffer(stress, &zero, sizeof(zero), 0, stress_bytes_);
  }
  return stress;
}

DeviceArrays::DeviceArrays(ClContext& cl, const Model& model)
    : num_nodes(model.num_nodes()),
      num_triangles(model.num_triangles()),
      num_loaded_edges(model.loaded_edges.size()),
      mass_scaling(model.mass_scaling) {
  const size_t n = num_nodes, t = num_triangles, e = num_loaded_edges;
  const MemoryPlan plan = DeviceArrays::plan(model);
  position = plan.allocate(cl, "position");
  velocity = plan.allocate(cl, "velocity");
  if (has_gravity(model)) ref_position = plan.allocate(cl, "ref_position");
  node_force = plan.allocate(cl, "node_force");
  node_mass = plan.allocate(cl, "node_mass");
  node_group = plan.allocate(cl, "node_group");
  group_table = plan.allocate(cl, "group_table");
  tri_nodes = plan.allocate(cl, "tri_nodes");
  ref_inverse = plan.allocate(cl, "ref_inverse");
  tri_material = plan.allocate(cl, "tri_material");
  materials = plan.allocate(cl, "materials");
  corner_force = plan.allocate(cl, "corner_force");
  stress_bytes_ = plan.bytes("stress");  // allocated for output steps only (output_stress)
  node_start = plan.allocate(cl, "node_start");
  node_slot = plan.allocate(cl, "node_slot");
  edge_nodes = plan.allocate(cl, "edge_nodes");
  edge_ref_position = plan.allocate(cl, "edge_ref_position");
  edge_load = plan.allocate(cl, "edge_load");
  load_table = plan.allocate(cl, "load_table");
  pressure_points = plan.allocate(cl, "pressure_points");
  edge_force = plan.allocate(cl, "edge_force");
  contact_acc = plan.allocate(cl, "contact_acc");
  conditions = plan.allocate(cl, "conditions");
  young_count = model.young_count();
  if (young_count > 0) {
    young_first = model.young_first();
    young_factor = plan.allocate(cl, "young_factor");
    std::vector<real> factor(young_count);
    for (size_t k = 0; k < young_count; ++k) factor[k] = real(model.young_factor[young_first + k]);
    upload(cl, young_factor, factor);
  }
  const SlotMap ce4 = build_slot_map(n, model.ce4);

  const std::vector<real2> pos = reference_positions(model);
  std::vector<real2> vel(n);
  for (size_t i = 0; i < n; ++i) vel[i] = {real(model.vx0[i]), real(model.vy0[i])};
  upload(cl, position, pos);
  if (has_gravity(model)) upload(cl, ref_position, pos);
  upload(cl, velocity, vel);
  upload(cl, node_group, model.node_group);
  std::vector<real4> groups;
  for (const auto& g : model.groups) groups.push_back({real(g.mask), real(g.vx), real(g.vy), real(g.rise)});
  upload(cl, group_table, groups);

  std::vector<uint32_t> tn(3 * t), tm(t);
  std::vector<real4> inv(t);
  for (size_t k = 0; k < t; ++k) {
    const auto& tri = model.triangles[k];
    for (int j = 0; j < 3; ++j) tn[3 * k + j] = static_cast<uint32_t>(tri[j]);
    tm[k] = static_cast<uint32_t>(model.triangle_material[k]);
    const double a = model.x[tri[1]] - model.x[tri[0]], b = model.x[tri[2]] - model.x[tri[0]];
    const double c = model.y[tri[1]] - model.y[tri[0]], d = model.y[tri[2]] - model.y[tri[0]];
    const double det = a * d - b * c;  // > 0: build_model oriented every triangle
    inv[k] = {real(d / det), real(-b / det), real(-c / det), real(a / det)};
  }
  upload(cl, tri_nodes, tn);
  upload(cl, tri_material, tm);
  upload(cl, ref_inverse, inv);
  std::vector<real> table;
  for (double v : material_table(model.materials)) table.push_back(real(v));
  upload(cl, materials, table);
  const SlotMap corners = build_slot_map(n, model.triangles);

  std::vector<uint32_t> en(2 * e), el(e);
  std::vector<std::array<int, 2>> edge_items(e);
  std::vector<uint32_t> row_of(model.loads.size());  // a load's first row in load_table
  for (size_t k = 0, row = 0; k < model.loads.size(); ++k) {
    row_of[k] = static_cast<uint32_t>(row);
    row += model.loads[k].kind == LoadKind::InSitu ? 2 : 1;
  }
  for (size_t k = 0; k < e; ++k) {
    const auto& edge = model.loaded_edges[k];
    en[2 * k] = static_cast<uint32_t>(edge.a);
    en[2 * k + 1] = static_cast<uint32_t>(edge.b);
    el[k] = row_of[edge.load];
    edge_items[k] = {edge.a, edge.b};
  }
  upload(cl, edge_nodes, en);
  std::vector<real2> edge_ref(2 * e);
  for (size_t k = 0; k < 2 * e; ++k) edge_ref[k] = pos[en[k]];
  upload(cl, edge_ref_position, edge_ref);
  upload(cl, edge_load, el);
  std::vector<real4> loads;
  std::vector<real2> points;
  for (const auto& l : model.loads) {
    const real kind = real(static_cast<int>(l.kind));
    switch (l.kind) {
      case LoadKind::Traction: loads.push_back({kind, real(l.tx), real(l.ty), real(l.rise)}); break;
      case LoadKind::Pressure: loads.push_back({kind, real(l.pressure), real(l.rise), 0}); break;
      case LoadKind::Blast: {
        const BlastPulse b = blast_pulse(l.pressure, l.rise, l.ratio);
        loads.push_back({kind, real(b.scale), real(b.alpha), real(b.beta)});
        break;
      }
      case LoadKind::Table:
        loads.push_back({kind, real(points.size()), real(l.times.size()), 0});
        for (size_t k = 0; k < l.times.size(); ++k) points.push_back({real(l.times[k]), real(l.values[k])});
        break;
      case LoadKind::Absorbing: loads.push_back({kind, real(l.material), 0, 0}); break;
      case LoadKind::Gas: loads.push_back({kind, 0, 0, 0}); break;
      case LoadKind::InSitu: {
        const InSituField& f = model.in_situ;
        loads.push_back({kind, real(f.uniform[0]), real(f.uniform[1]), real(f.uniform[2])});
        loads.push_back({real(f.datum), real(f.gradient[0]), real(f.gradient[1]), real(f.gradient[2])});
        break;
      }
    }
  }
  upload(cl, load_table, loads);
  if (points.empty()) points.push_back({0, 0});
  upload(cl, pressure_points, points);
  const SlotMap edges = build_slot_map(n, edge_items);
  {
    SlotMap map = node_slot_map(corners, edges, ce4);
    if (map.slot.empty()) map.slot.push_back(0);  // the plan's one entry
    upload(cl, node_start, map.start);
    upload(cl, node_slot, map.slot);
  }

  upload(cl, contact_acc, std::vector<cl_long>((model.contact.enabled ? n : 1) * 2, 0));
  upload(cl, conditions, std::vector<int>(layout::CONDITION_WORDS, INT_MAX));
  cl.finish();
}

}  // namespace fdem
