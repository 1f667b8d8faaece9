#include "engine/run/domain.hpp"

#include "base/errors.hpp"
#include "engine/run/split_run.hpp"
#include "engine/parallel/transport.hpp"

namespace fdem {

std::vector<io::BreakRecord> with_triangles(const Model& model, std::vector<io::BreakRecord> records) {
  for (auto& b : records) {
    b.tri_a = model.ce4_triangles[b.ce4][0], b.tri_b = model.ce4_triangles[b.ce4][1];
    if (!model.ce4_joint.empty()) b.joint = model.ce4_joint[b.ce4];
    if (!model.ce4_grain_boundary.empty()) b.grain_boundary = model.ce4_grain_boundary[b.ce4];
  }
  return records;
}

std::unique_ptr<Domain> make_whole_domain(const PreparedCase& p, ClContext& cl);
std::unique_ptr<Domain> make_split_domain(const PreparedCase& p, ClContext& cl, Transport& transport,
                                          PartitionMethod partition, double travel);

std::unique_ptr<Domain> make_domain(const PreparedCase& p, ClContext& cl, Transport* transport,
                                    PartitionMethod partition, double contact_travel, const std::function<void()>& setup) {
  if (!transport || transport->size() <= 1) {
    setup();
    return make_whole_domain(p, cl);
  }
  // Every rank finds the same start-up errors, or agrees on the first.
  std::unique_ptr<Domain> domain;
  std::exception_ptr failure;
  try {
    setup();
    if (p.model.fluid.enabled)  // the flow network is not split over ranks yet (issue 32)
      throw InputError(p.config.path + ": [fluid] runs on one rank only; run it without mpirun");
    domain = make_split_domain(p, cl, *transport, partition, contact_travel);
  } catch (...) {
    failure = std::current_exception();
  }
  agree(*transport, failure);
  return domain;
}

}  // namespace fdem
