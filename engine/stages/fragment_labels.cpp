#include "engine/stages/fragment_labels.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "engine/device/device_arrays.hpp"
#include "base/errors.hpp"

namespace fdem {

MemoryPlan FragmentLabels::plan(size_t triangles, size_t nodes, size_t ce4) {
  return MemoryPlan()
      .add("fragment_label", (triangles + nodes) * sizeof(cl_int), MemoryPlan::Lifetime::Output)
      .add("fragment_ce4_triangles", 2 * ce4 * sizeof(cl_uint))
      .add("fragment_changed", sizeof(cl_int));
}

FragmentLabels::FragmentLabels(ClContext& cl, size_t triangles, size_t nodes, compute::buffer& tri_nodes,
                               const std::vector<std::array<int, 2>>& ce4_triangles, compute::buffer* status)
    : cl_(cl), triangles_(triangles), vertices_(triangles + nodes), ce4_(ce4_triangles.size()) {
  if (ce4_ && !status) throw DeviceError("fragment labels: CE4s without their status array");
  const MemoryPlan arrays = plan(triangles, nodes, ce4_);
  label_bytes_ = arrays.bytes("fragment_label");  // allocated by labels() for the call only
  pairs_ = arrays.allocate(cl, "fragment_ce4_triangles");
  changed_ = arrays.allocate(cl, "fragment_changed");
  std::vector<cl_uint> pairs;
  for (const auto& t : ce4_triangles) {
    if (t[0] < 0 || t[1] < 0 || size_t(t[0]) >= triangles || size_t(t[1]) >= triangles)
      throw DeviceError("fragment labels: a CE4 names a triangle out of range");
    pairs.insert(pairs.end(), {cl_uint(t[0]), cl_uint(t[1])});
  }
  if (!pairs.empty()) upload(cl, pairs_, pairs);

  const compute::program program = cl.build(kernel_source::fragments);
  init_ = compute::kernel(program, "fragment_init");
  {
    KernelArgs args(init_);
    args("n_vertices", cl_uint(vertices_));
    label_args_.push_back(args.later("label", changed_));
    args.done();
  }
  hook_triangles_ = compute::kernel(program, "fragment_hook_triangles");
  {
    KernelArgs args(hook_triangles_);
    args("n_tri", cl_uint(triangles))("tri_nodes", tri_nodes);
    label_args_.push_back(args.later("label", changed_));
    args("changed", changed_).done();
  }
  hook_ce4_ = compute::kernel(program, "fragment_hook_ce4");
  {
    KernelArgs args(hook_ce4_);
    args("n_ce4", cl_uint(ce4_))("status", status ? *status : pairs_)("ce4_triangles", pairs_);
    label_args_.push_back(args.later("label", changed_));
    args("changed", changed_).done();
  }
  shortcut_ = compute::kernel(program, "fragment_shortcut");
  {
    KernelArgs args(shortcut_);
    args("n_vertices", cl_uint(vertices_));
    label_args_.push_back(args.later("label", changed_));
    args.done();
  }
}

std::vector<int> FragmentLabels::labels() {
  rounds_ = 0;
  if (triangles_ == 0) return {};
  // The labels live for this call only (an output array: 16 B/TRI3 of the bench model).
  auto began = std::chrono::steady_clock::now();
  auto lap = [&](const char* what) {  // the profile's split of a labelling
    if (!cl_.profiling()) return;
    cl_.finish();
    const auto now = std::chrono::steady_clock::now();
    cl_.add_host_time(std::string("  fragment labelling: ") + what, std::chrono::duration<double>(now - began).count());
    began = now;
  };
  const compute::buffer label = cl_.allocate(label_bytes_, "fragment_label");
  for (auto& arg : label_args_) arg.set(label);
  lap("allocation");
  cl_.enqueue(init_, vertices_);
  const cl_int zero = 0;
  // A round that hooks nothing ends it (later ones would hook nothing either). On a GPU
  // the flag is read after the fourth round, then after every second: a read waits for
  // the device (about 60 µs on the H200 against 15 for a round's launches), and a
  // labelling takes about seven rounds. A CPU reads it after each (launches cost more there).
  for (;;) {
    ++rounds_;
    cl_.queue().enqueue_fill_buffer(changed_, &zero, sizeof(zero), 0, sizeof(zero));
    cl_.enqueue(hook_triangles_, triangles_);
    if (ce4_) cl_.enqueue(hook_ce4_, ce4_);
    cl_.enqueue(shortcut_, vertices_);
    if (cl_.info().is_gpu && (rounds_ < 4 || rounds_ % 2 == 1)) continue;
    if (download<cl_int>(cl_, changed_, 1)[0] == 0) break;
  }
  lap("rounds");
  auto out = download<cl_int>(cl_, label, triangles_);
  lap("labels read");
  for (auto& arg : label_args_) arg.set(changed_);  // no kernel keeps the released array
  return out;
}

}  // namespace fdem
