// Fuzz target: Gmsh MSH 2.2 and 4.1, ASCII and binary (io/gmsh_msh.cpp on the byte
// buffer of io/gmsh_buffer.hpp), then what the engine does with a mesh it accepted: one
// refinement (io/mesh_refine.cpp) and a model with a fracturable material on every
// physical surface (engine/model/model.cpp: CE4 insertion, boundary curves) and its stable step.
#include <string>
#include <vector>

#include "engine/model/model.hpp"
#include "fuzz_common.hpp"
#include "io/case_config.hpp"
#include "io/gmsh_reader.hpp"

namespace {

fdem::io::CaseConfig config_for(const fdem::io::Mesh& mesh, const std::string& path) {
  fdem::io::CaseConfig c;
  c.path = path;
  c.dir = fdem::fuzz::scratch_dir();
  c.mesh.file = path;
  for (const auto& group : mesh.groups) {
    if (group.dim != 2) continue;
    fdem::io::MaterialConfig m;
    m.name = "m" + std::to_string(c.materials.size());
    m.regions = {group.name};
    m.density = 2700;
    m.young = 30e9;
    m.poisson = 0.25;
    m.viscosity_critical = true;
    fdem::io::FractureConfig f;
    f.tensile_strength = 5e6;
    f.cohesion = 10e6;
    f.friction_angle = 30;
    f.gf1 = 20;
    f.gf2 = 100;
    f.penalty_opening = f.penalty_sliding = f.penalty_overlap = 300e9;
    m.fracture = f;
    c.materials.push_back(m);
  }
  return c;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fdem::fuzz::no_programs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = fdem::fuzz::write_input("mesh.msh", data, size);
  try {
    std::vector<std::string> notes;
    fdem::io::Mesh mesh = fdem::io::read_gmsh(path, &notes);
    const fdem::io::CaseConfig c = config_for(mesh, path);
    // The model of a large mesh is slow to build and adds no new paths.
    if (mesh.triangles.size() <= 2000) fdem::stable_time_step(fdem::build_model(mesh, c, notes));
    if (mesh.triangles.size() <= 500) fdem::io::refine_mesh(mesh, 1);
  } catch (const fdem::InputError&) {
  }
  return 0;
}
