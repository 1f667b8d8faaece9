#include "engine/stages/extrinsic.hpp"

#include <algorithm>
#include <map>
#include <string>

namespace fdem {

namespace {

MemoryPlan plan_of(const ExtrinsicTies& t, size_t ce4) {
  MemoryPlan p;
  p.add("extrinsic copy_start", t.copy_start.size() * sizeof(cl_uint))
      .add("extrinsic copy_node", std::max<size_t>(1, t.copy_node.size()) * sizeof(cl_uint))
      .add("extrinsic link_start", t.link_start.size() * sizeof(cl_uint))
      .add("extrinsic link", std::max<size_t>(1, t.link.size()) * 4 * sizeof(cl_uint))
      .add("extrinsic whole", std::max<size_t>(1, t.whole.size()) * sizeof(cl_uchar))
      .add("extrinsic opposite", std::max<size_t>(1, ce4) * 2 * sizeof(cl_uint))
      .add("extrinsic ce4_vertex", std::max<size_t>(1, ce4) * 2 * sizeof(cl_uint));
  return p;
}

}  // namespace

MemoryPlan Extrinsic::plan(const Model& model) { return plan_of(extrinsic_ties(model), model.ce4.size()); }

Extrinsic::Extrinsic(ClContext& cl, DeviceArrays& arrays, const Model& model, CohesiveForces& cohesive)
    : cl_(cl), ce4_(model.ce4.size()) {
  if (model.mass_scaling) throw InputError("extrinsic CE4s: mass scaling is not supported");
  if (!cohesive.extrinsic()) throw DeviceError("extrinsic stage: the CE4 stage was built without extrinsic CE4s");
  const ExtrinsicTies ties = extrinsic_ties(model);
  vertices_ = ties.vertices();
  const MemoryPlan p = plan_of(ties, ce4_);
  copy_start_ = p.allocate(cl, "extrinsic copy_start");
  copy_node_ = p.allocate(cl, "extrinsic copy_node");
  link_start_ = p.allocate(cl, "extrinsic link_start");
  link_ = p.allocate(cl, "extrinsic link");
  whole_ = p.allocate(cl, "extrinsic whole");
  if (!ties.whole.empty()) upload(cl, whole_, std::vector<cl_uchar>(ties.whole.begin(), ties.whole.end()));
  opposite_ = p.allocate(cl, "extrinsic opposite");
  ce4_vertex_ = p.allocate(cl, "extrinsic ce4_vertex");
  std::vector<cl_uint> ends;
  for (const auto& o : ties.ce4_vertex) ends.insert(ends.end(), o.begin(), o.end());
  if (!ends.empty()) upload(cl, ce4_vertex_, ends);
  upload(cl, copy_start_, std::vector<cl_uint>(ties.copy_start.begin(), ties.copy_start.end()));
  if (!ties.copy_node.empty()) upload(cl, copy_node_, std::vector<cl_uint>(ties.copy_node.begin(), ties.copy_node.end()));
  upload(cl, link_start_, std::vector<cl_uint>(ties.link_start.begin(), ties.link_start.end()));
  std::vector<cl_uint> links;
  for (const auto& l : ties.link) links.insert(links.end(), l.begin(), l.end());
  if (!links.empty()) upload(cl, link_, links);
  std::vector<cl_uint> opposite;
  for (const auto& o : ties.opposite) opposite.insert(opposite.end(), o.begin(), o.end());
  if (!opposite.empty()) upload(cl, opposite_, opposite);

  const std::map<std::string, std::string> defines{{"EXTRINSIC_MAX_COPIES", std::to_string(kExtrinsicMaxCopies)}};
  const auto program = cl.build(kernel_source::extrinsic, defines);
  tie_ = compute::kernel(program, "extrinsic_tie");
  bind_args(tie_)("n_vertices", cl_uint(vertices_))("copy_start", copy_start_)("copy_node", copy_node_)(
      "link_start", link_start_)("link", link_)("whole", whole_)("inserted", cohesive.inserted())("node_mass", arrays.node_mass)(
      "position", arrays.position)("velocity", arrays.velocity)
      .done();
  insert_ = compute::kernel(program, "extrinsic_insert");
  bind_args(insert_)("n_ce4", cl_uint(ce4_))("ce4_nodes", cohesive.nodes())("ce4_length", cohesive.lengths())(
      "property", cohesive.property())("property_rows", cohesive.property_rows())("opposite", opposite_)(
      "position", arrays.position)("corner_force", arrays.corner_force)("thickness", real(model.thickness))(
      "inserted", cohesive.inserted())("gaps", cohesive.insertion_gaps())("gp_slip", cohesive.friction_slips())(
      "inserted_count", cohesive.inserted_count_buffer())("ce4_vertex", ce4_vertex_)("whole", whole_)
      .done();
  mark_ = compute::kernel(program, "extrinsic_mark");
  bind_args(mark_)("n_vertices", cl_uint(vertices_))("link_start", link_start_)("link", link_)("inserted",
      cohesive.inserted())("whole", whole_)
      .done();
}

void Extrinsic::mark_inserted() {
  if (vertices_ > 0) cl_.enqueue(mark_, vertices_);
}

void Extrinsic::enqueue_tie() {
  if (vertices_ > 0) cl_.enqueue(tie_, vertices_);
}

void Extrinsic::enqueue_insert() {
  if (ce4_ > 0) cl_.enqueue(insert_, ce4_);
}

}  // namespace fdem
