// Exodus frames and the fragments file written with them (engine/outputs/outputs.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/outputs/fragments.hpp"
#include "engine/outputs/outputs.hpp"
#include "io/exodus_writer.hpp"
#include "io/fragment_writer.hpp"

namespace fdem {

namespace {

std::vector<std::string> element_names(const Model& model) {
  std::vector<std::string> names = {"SXX", "SYY", "SXY", "PS1", "PS2"};
  if (!model.ce4.empty()) names.insert(names.end(), {"DAMAGE", "BROKEN", "MODE", "OPENING", "SLIP", "FRAGMENT"});
  // [[joint]]: on the cohesive block the joint's number (joint[k]: k + 1) of each CE4, 0
  // off the joints and on the triangles; a Threshold JOINT >= 1 shows the joints.
  if (!model.ce4_joint.empty()) names.push_back("JOINT");
  // [grains]: on the triangles the grain's number (grain k: k + 1), 0 outside the grains'
  // region and on the cohesive block.
  if (!model.triangle_grain.empty()) names.push_back("GRAIN");
  // [[excavation]]: how much of each triangle (and CE4) is removed, 0 (whole) to 1
  // (gone); a Threshold EXCAVATED < 1 in ParaView shows the hole.
  if (!model.excavations.empty()) names.push_back("EXCAVATED");
  // [fluid]: the network on the cohesive block (each CE4 a segment): the mean pressure of
  // its two vertices and its mean aperture, 0 where it carries no fluid and on triangles.
  if (model.fluid.enabled) names.insert(names.end(), {"FLUID_PRESSURE", "FLUID_APERTURE"});
  return names;
}

std::vector<std::string> nodal_names(const Model& model) {
  std::vector<std::string> names = {"DISPLX", "DISPLY", "VELX", "VELY"};
  if (model.contact.enabled) names.insert(names.end(), {"CONTACT_FX", "CONTACT_FY"});
  return names;
}

std::vector<io::ExodusBlock> blocks(const Model& model) {
  std::vector<io::ExodusBlock> out;
  for (size_t m = 0; m < model.materials.size(); ++m) {
    io::ExodusBlock block{model.materials[m].name, "TRI3", 3, {}};
    for (size_t t = model.block_start[m]; t < model.block_start[m + 1]; ++t)
      block.connectivity.insert(block.connectivity.end(), model.triangles[t].begin(), model.triangles[t].end());
    if (!block.connectivity.empty()) out.push_back(std::move(block));
  }
  if (!model.ce4.empty()) {
    // Nodes (i, j, j', i'): a zero-area quadrilateral that opens as the crack does.
    io::ExodusBlock block{"cohesive", "QUAD4", 4, {}};
    for (const auto& c : model.ce4) block.connectivity.insert(block.connectivity.end(), c.begin(), c.end());
    out.push_back(std::move(block));
  }
  return out;
}

class ExodusFrames : public Output {
 public:
  ExodusFrames(const PreparedCase& p, Trigger trigger, ClContext& cl)
      : Output(p.exodus_path, std::move(trigger)), p_(p), model_(p.model), cl_(cl) {}
  Role role() const override { return Role::Frame; }
  Needs needs() const override {
    Needs n = Need::Positions | Need::Velocities | Need::Stress | Need::GoodCopy;
    if (model_.contact.enabled) n |= Need::ContactForces;
    if (!model_.ce4.empty()) n |= Need::Ce4Flags | Need::Ce4State | Need::FragmentLabels;
    if (model_.fluid.enabled) n |= Need::FluidSegments;
    return n;
  }
  void open(const std::string& partial, const Snapshot&) override {
    file_ = std::make_unique<io::ExodusWriter>(
        partial, p_.config.title, model_.x, model_.y, blocks(model_), nodal_names(model_), element_names(model_),
        io::ExodusOptions{p_.config.output.float_frames, p_.config.output.compress});
  }
  void write(const Snapshot& f) override;
  bool resume(const io::ResumeCopy& copy) override { return io::copy_exodus_frames(path(), *file_, copy) >= 0; }
  const char* digest_key() const override { return kExodusDigests; }
  std::vector<std::uint64_t> digests() const override { return file_->frame_digests(); }
  void moved_to(const std::string& path) override { file_->moved_to(path); }
  void finish(const Snapshot&) override { file_->close(); }
  void add_totals(OutputTotals& t) const override { t.frames = file_->frames_written(); }

 private:
  const PreparedCase& p_;
  const Model& model_;
  ClContext& cl_;
  std::unique_ptr<io::ExodusWriter> file_;
};

void ExodusFrames::write(const Snapshot& f) {
  const Model& model = model_;
  const auto& x = f.positions;
  const auto& v = f.velocities;
  const auto& stress = f.stress;
  const size_t n = model.num_nodes();
  std::vector<std::vector<double>> nodal(model.contact.enabled ? 6 : 4, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    nodal[0][i] = x[i].x - model.x[i];
    nodal[1][i] = x[i].y - model.y[i];
    nodal[2][i] = v[i].x;
    nodal[3][i] = v[i].y;
  }
  if (model.contact.enabled) {
    const auto& fc = f.contact_forces;
    for (size_t i = 0; i < n; ++i) nodal[4][i] = fc[i].x, nodal[5][i] = fc[i].y;
  }
  const bool fracture = !model.ce4.empty();
  std::vector<std::vector<std::vector<double>>> elem(element_names(model).size());
  for (size_t m = 0; m < model.materials.size(); ++m) {
    const size_t begin = model.block_start[m], end = model.block_start[m + 1];
    if (begin == end) continue;
    for (auto& var : elem) var.emplace_back(fracture ? end - begin : 0, 0.0);
    for (size_t t = begin; t < end; ++t) {
      const double sxx = stress[t].x, syy = stress[t].y, sxy = stress[t].z;
      const double centre = 0.5 * (sxx + syy), radius = std::hypot(0.5 * (sxx - syy), sxy);
      const double values[5] = {sxx, syy, sxy, centre + radius, centre - radius};
      for (int k = 0; k < 5; ++k) {
        if (fracture) elem[k].back()[t - begin] = values[k];
        else elem[k].back().push_back(values[k]);
      }
    }
  }
  if (fracture) {  // the cohesive block: CE4 variables, zero stresses
    const size_t count = model.ce4.size();
    for (auto& var : elem) var.emplace_back(count, 0.0);
    // FRAGMENT: the piece's id (Exodus element number of its first triangle) on every
    // triangle; on an intact CE4 its triangles' piece, on a broken one 0.
    const auto& labels = f.labels;
    for (size_t m = 0, b = 0; m < model.materials.size(); ++m) {
      const size_t begin = model.block_start[m], end = model.block_start[m + 1];
      if (begin == end) continue;
      for (size_t t = begin; t < end; ++t) elem[10][b][t - begin] = labels[t] + 1;
      ++b;
    }
    for (size_t e = 0; e < count; ++e) {
      elem[5].back()[e] = f.damage[e];
      elem[6].back()[e] = f.broken[e];
      elem[7].back()[e] = f.mode[e];
      elem[8].back()[e] = f.opening[e];
      elem[9].back()[e] = f.slip[e];
      elem[10].back()[e] = f.broken[e] ? 0 : labels[model.ce4_triangles[e][0]] + 1;
    }
    if (!model.ce4_joint.empty())
      for (size_t e = 0; e < count; ++e) elem[11].back()[e] = model.ce4_joint[e] + 1;
  }
  if (!model.triangle_grain.empty()) {  // after JOINT, before EXCAVATED: 0 on the CE4 block
    const size_t k = elem.size() - 1 - (model.excavations.empty() ? 0 : 1) - (model.fluid.enabled ? 2 : 0);
    for (size_t m = 0, b = 0; m < model.materials.size(); ++m) {
      const size_t begin = model.block_start[m], end = model.block_start[m + 1];
      if (begin == end) continue;
      elem[k][b].assign(end - begin, 0.0);
      for (size_t t = begin; t < end; ++t) elem[k][b][t - begin] = model.triangle_grain[t] + 1;
      ++b;
    }
  }
  if (!model.excavations.empty()) {  // after the CE4 variables
    const size_t k = elem.size() - 1 - (model.fluid.enabled ? 2 : 0);
    const std::vector<double> keep = excavation_factors(model, f.time);
    size_t b = 0;
    for (size_t m = 0; m < model.materials.size(); ++m) {
      const size_t begin = model.block_start[m], end = model.block_start[m + 1];
      if (begin == end) continue;
      elem[k][b].assign(end - begin, 0.0);
      for (size_t t = begin; t < end; ++t) elem[k][b][t - begin] = 1.0 - keep[t];
      ++b;
    }
    // On the CE4 block: 1 − the CE4's factor, the smaller of its two triangles'
    // (cl_kernels/cohesive_forces.cl, EXCAVATION); 0 for CE4s off the excavations.
    if (b < elem[k].size() && !model.ce4_triangles.empty()) {
      elem[k][b].assign(model.ce4_triangles.size(), 0.0);
      for (size_t e = 0; e < model.ce4_triangles.size(); ++e)
        elem[k][b][e] = 1.0 - std::min(keep[model.ce4_triangles[e][0]], keep[model.ce4_triangles[e][1]]);
    }
  }
  if (model.fluid.enabled) {  // the last two variables, on the CE4 block only (the last block)
    const size_t k = elem.size() - 2;
    for (size_t b = 0; b + 1 < elem[k].size(); ++b) elem[k][b].assign(elem[k][b].size(), 0.0), elem[k + 1][b].assign(elem[k + 1][b].size(), 0.0);
    elem[k].back().assign(f.fluid_pressure.begin(), f.fluid_pressure.end());
    elem[k + 1].back().assign(f.fluid_aperture.begin(), f.fluid_aperture.end());
  }
  const auto began = std::chrono::steady_clock::now();
  file_->write_frame(f.time, nodal, elem);
  if (cl_.profiling())
    cl_.add_host_time("Exodus frame write (host wall, incl. sync)",
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
}

class FragmentFrames : public Output {
 public:
  FragmentFrames(const PreparedCase& p, Trigger trigger) : Output(p.fragments_path, std::move(trigger)), p_(p) {}
  Role role() const override { return Role::Frame; }
  Needs needs() const override { return Need::Positions | Need::Ce4Flags | Need::FragmentLabels | Need::GoodCopy; }
  void open(const std::string& partial, const Snapshot&) override {
    file_ = std::make_unique<io::FragmentWriter>(partial, p_.config.title);
  }
  void write(const Snapshot& f) override {
    file_->write_frame(f.time, summarise_fragments(p_.model, f.labels, f.positions).fragments);
  }
  bool resume(const io::ResumeCopy& copy) override { return io::copy_fragment_frames(path(), *file_, copy) >= 0; }
  const char* digest_key() const override { return kFragmentDigests; }
  std::vector<std::uint64_t> digests() const override { return file_->frame_digests(); }
  void moved_to(const std::string& path) override { file_->moved_to(path); }
  void finish(const Snapshot&) override { file_->close(); }

 private:
  const PreparedCase& p_;
  std::unique_ptr<io::FragmentWriter> file_;
};

}  // namespace

std::unique_ptr<Output> exodus_frames(const PreparedCase& p, Trigger trigger, ClContext& cl) {
  return std::make_unique<ExodusFrames>(p, std::move(trigger), cl);
}

std::unique_ptr<Output> fragment_frames(const PreparedCase& p, Trigger trigger) {
  return std::make_unique<FragmentFrames>(p, std::move(trigger));
}

}  // namespace fdem
