// Excavation ([[excavation]], docs/case-format.md): regions of the model removed at a time
// or over a time. A removed triangle's internal force (elastic, in-situ and viscous) and
// its stored strain energy are scaled by its excavation's factor, which falls linearly
// from 1 to 0 (cl_kernels/triangle_forces.cl, EXCAVATION); the strain energy that leaves
// with it is the account's `excavated` term (docs/energy-notes.md, "Excavation"). CE4s
// with a removed triangle ramp with the smaller factor of their two (cohesive_forces.cl),
// and contact drops the couples of removed triangles (contact_forces.cl).
#pragma once
#include <string>
#include <vector>

#include "io/case_config.hpp"
#include "io/mesh.hpp"

namespace fdem {

struct Model;

struct Excavation {
  std::string region;     // the physical surface removed
  double start = 0;       // [s]
  double duration = 0;    // [s]; 0: at once
  // The factor on the region's forces at time t: 1 before `start`, 0 from
  // start + duration on, linear between (with duration 0: 0 from `start` on).
  double factor(double t) const {
    if (t < start) return 1.0;
    if (!(duration > 0) || t >= start + duration) return 0.0;
    return 1.0 - (t - start) / duration;
  }
};

// Sets model.excavations and model.triangle_excavation from config.excavations;
// `triangle_group[t]` is the mesh's physical group (index into mesh.groups) of model
// triangle t. Throws InputError naming the case file and the key: a region that is not a
// physical surface of the mesh (with a suggestion), a surface of no material, and CE4s
// in or on the edge of the region that are extrinsic or may carry [fluid] (not supported
// yet). CE4s there ramp with the region, and with [contact] its triangles leave contact
// when their ramp starts. Nothing happens without entries.
void set_excavations(Model& model, const io::Mesh& mesh, const std::vector<int>& triangle_group,
                     const io::CaseConfig& config);

// The factor 1 - removal of every triangle at time t (1: whole, 0: removed); for output.
std::vector<double> excavation_factors(const Model& model, double t);

// What `fdem check` says of each excavation: region, triangles, start and end.
std::vector<std::string> excavation_summary(const Model& model);

}  // namespace fdem
