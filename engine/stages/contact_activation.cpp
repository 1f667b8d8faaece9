#include "engine/stages/contact_activation.hpp"

#include <algorithm>
#include <map>
#include <string>

namespace fdem {

MemoryPlan ContactActivation::plan(size_t ce4, bool owned) {
  MemoryPlan p;
  if (owned) p.add("activation ce4_owned", std::max<size_t>(ce4, 1) * sizeof(cl_uchar));
  return p;
}

ContactActivation::ContactActivation(ClContext& cl, size_t ce4, const compute::buffer& ce4_triangles,
                                     compute::buffer& status, compute::buffer& active, MonitorRing& ring,
                                     const std::vector<char>& owned)
    : cl_(cl), count_(ce4), triangles_(ce4_triangles) {
  const MemoryPlan arrays = plan(count_, !owned.empty());
  std::map<std::string, std::string> defines;
  if (!owned.empty()) {
    if (owned.size() != count_) throw DeviceError("contact activation: the owned-CE4 mask has the wrong size");
    defines["OWNED_FLAG"] = "1";
    owned_ = arrays.allocate(cl, "activation ce4_owned");
    upload(cl, owned_, std::vector<cl_uchar>(owned.begin(), owned.end()));
  }
  kernel_ = compute::kernel(cl.build(kernel_source::contact_activation, defines), "activate_broken");
  KernelArgs args(kernel_);
  args("n_ce4", static_cast<cl_uint>(count_))("status", status)("ce4_triangles", triangles_)("active", active)(
      "monitor", ring.buffer());
  if (!owned.empty()) args("ce4_owned", owned_);
  slot_ = args.later("slot", cl_uint(0));
  stamp_ = args.later("stamp", cl_uint(0));
  args.done();
}

void ContactActivation::enqueue(long step) {
  if (count_ == 0) return;
  slot_.set(MonitorRing::slot_of(step));
  stamp_.set(join_stamp(step));
  cl_.enqueue(kernel_, count_);
}

}  // namespace fdem
