#include "engine/model/excavation.hpp"

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/model/model.hpp"
#include "io/suggest.hpp"

namespace fdem {

void set_excavations(Model& model, const io::Mesh& mesh, const std::vector<int>& triangle_group,
                     const io::CaseConfig& config) {
  model.excavations.clear();
  model.triangle_excavation.clear();
  if (config.excavations.empty()) return;
  model.triangle_excavation.assign(model.num_triangles(), -1);
  for (size_t i = 0; i < config.excavations.size(); ++i) {
    const auto& c = config.excavations[i];
    const std::string key = "excavation." + std::to_string(i) + ".region";
    const std::string name = "excavation[" + std::to_string(i) + "].region = \"" + c.region + "\"";
    auto fail = [&](const std::string& what) -> void {
      throw InputError(io::origin_of(config, key) + ": " + name + ": " + what);
    };
    const int group = mesh.find_group(c.region, 2);
    if (group < 0) {
      std::vector<std::string> surfaces;
      for (const auto& g : mesh.groups)
        if (g.dim == 2 && !g.name.empty()) surfaces.push_back(g.name);
      std::string list;
      for (const auto& s : surfaces) list += (list.empty() ? "'" : ", '") + s + "'";
      fail("no physical surface of that name in " + mesh.source + io::did_you_mean(c.region, surfaces) +
           "; its surfaces are " + (list.empty() ? "(none)" : list));
    }
    size_t count = 0;
    for (size_t t = 0; t < model.num_triangles(); ++t)
      if (triangle_group[t] == group) {
        if (model.triangle_excavation[t] >= 0)
          fail("its triangles are already excavated by excavation[" + std::to_string(model.triangle_excavation[t]) + "]");
        model.triangle_excavation[t] = static_cast<int>(i);
        ++count;
      }
    if (count == 0) fail("the surface has no triangles in the model (is it in a material's regions?)");
    if (count == model.num_triangles()) fail("it is the whole model: nothing would be left");
    model.excavations.push_back({c.region, c.start, c.duration});
  }
  // CE4s in or on the edge of an excavated region ramp with it (cl_kernels/cohesive_forces.cl,
  // EXCAVATION). What is not supported yet is refused here, naming the excavation's key.
  for (size_t e = 0; e < model.ce4_triangles.size(); ++e)
    for (int t : model.ce4_triangles[e])
      if (model.triangle_excavation[t] >= 0) {
        const int i = model.triangle_excavation[t];
        const std::string where = io::origin_of(config, "excavation." + std::to_string(i) + ".region") +
                                  ": excavation[" + std::to_string(i) + "].region = \"" +
                                  config.excavations[i].region + "\": ";
        const int set = e < model.ce4_properties.size() ? model.ce4_properties[e] : -1;
        if (set >= 0 && static_cast<size_t>(set) < model.fracture.size() && model.fracture[set].extrinsic)
          throw InputError(where + "extrinsic CE4s (fracture.model = \"extrinsic\") join its triangles; excavating "
                                   "extrinsic CE4s is not supported yet: give the excavated surface and its "
                                   "neighbours an intrinsic fracture model or none");
        if (config.fluid)
          throw InputError(where + "CE4s join its triangles and the case has [fluid]; excavating CE4s that may "
                                   "carry fluid is not supported yet: make the excavated surface and its "
                                   "neighbours' shared edges non-fracturable, or leave out [fluid]");
      }
  // With [contact], a couple takes no part in contact from the step one of its triangles
  // starts to be excavated (cl_kernels/contact_forces.cl, EXCAVATION).
}

std::vector<double> excavation_factors(const Model& model, double t) {
  std::vector<double> out(model.num_triangles(), 1.0);
  for (size_t k = 0; k < model.triangle_excavation.size(); ++k)
    if (model.triangle_excavation[k] >= 0) out[k] = model.excavations[model.triangle_excavation[k]].factor(t);
  return out;
}

std::vector<std::string> excavation_summary(const Model& model) {
  std::vector<std::string> out;
  for (size_t i = 0; i < model.excavations.size(); ++i) {
    const auto& e = model.excavations[i];
    size_t count = 0;
    for (int x : model.triangle_excavation) count += x == static_cast<int>(i);
    // The CE4s that go with it: in the region or on its edge (the smaller factor of their
    // two triangles is this excavation's while it ramps).
    size_t ce4s = 0;
    for (const auto& pair : model.ce4_triangles)
      ce4s += model.triangle_excavation[pair[0]] == static_cast<int>(i) ||
              model.triangle_excavation[pair[1]] == static_cast<int>(i);
    out.push_back("'" + e.region + "': " + std::to_string(count) + " triangles" +
                  (ce4s > 0 ? " and " + std::to_string(ce4s) + " CE4s" : std::string()) + " removed " +
                  (e.duration > 0 ? "from t = " + format_number(e.start, 6) + " s to " +
                                        format_number(e.start + e.duration, 6) + " s (forces ramped to zero)"
                                  : "at t = " + format_number(e.start, 6) + " s (at once)"));
  }
  return out;
}

}  // namespace fdem
