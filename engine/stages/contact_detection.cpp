#include "engine/stages/contact_detection.hpp"

#include <algorithm>
#include <map>
#include <boost/compute/algorithm/detail/radix_sort.hpp>
#include <boost/compute/algorithm/sort.hpp>
#include <boost/compute/algorithm/sort_by_key.hpp>
#include <boost/compute/exception.hpp>
#include <boost/compute/iterator/buffer_iterator.hpp>
#include <string>

#include "base/errors.hpp"
#include "engine/kernel_args.hpp"

namespace fdem {

namespace {

template <typename T>
compute::buffer_iterator<T> at(const compute::buffer& b, size_t i) {
  return compute::make_buffer_iterator<T>(b, i);
}

// Most grid cells a run may use: 4 per triangle + 1024.
size_t cell_limit(size_t triangles) { return 4 * triangles + 1024; }

// Device memory a Boost.Compute sort of `count` keys (and values) takes besides its
// input: one copy of the keys and of the values, and in its radix sort 16 uint offsets
// plus 16 uint counters per block of 128 (its merge sorts need only the copies).
size_t sort_scratch(size_t count, size_t key_bytes, size_t value_bytes) {
  return count * (key_bytes + value_bytes) + 16 * sizeof(cl_uint) * (1 + (count + 127) / 128);
}

}  // namespace

MemoryPlan ContactDetection::couple_list(size_t capacity) {
  return MemoryPlan().add("contact couples", capacity * sizeof(cl_ulong));
}

MemoryPlan ContactDetection::plan(size_t triangles, size_t group_size, size_t initial_capacity, bool bonds,
                                  bool owned_first) {
  const size_t n = std::max<size_t>(triangles, 1), groups = std::max<size_t>(groups_for(triangles, group_size), 1);
  const size_t capacity = first_capacity(triangles, initial_capacity);
  MemoryPlan p;
  using L = MemoryPlan::Lifetime;
  // Boxes, cells, hashes and sorted triangles: used only while a detection finds its
  // couples, allocated by run() for that and released before the couples' sort.
  p.add("contact boxes", n * sizeof(real4), L::Detection)
      .add("contact partial bounds", groups * sizeof(real4))
      .add("contact partial sides", groups * sizeof(real))
      .add("contact grid", sizeof(real4))
      .add("contact grid size", 4 * sizeof(cl_uint))
      .add("contact cell first", cell_limit(triangles) * sizeof(cl_uint), L::Detection)
      .add("contact cell last", cell_limit(triangles) * sizeof(cl_uint), L::Detection)
      .add("contact hashes", n * sizeof(cl_uint), L::Detection)
      .add("contact sorted triangles", n * sizeof(cl_uint), L::Detection)
      .add("contact active mask", n * sizeof(cl_uint))
      .add("contact couple counter", sizeof(cl_uint))
      .add(couple_list(capacity));
  if (bonds) p.add("contact bond partners", 3 * n * sizeof(cl_uint));
  if (owned_first) p.add("contact owned triangles", n * sizeof(cl_uchar));
  // The two sorts of a run, one after the other; the couples' at the first capacity. The
  // hashes' sort runs while the detection arrays above exist (counted with them).
  p.add("sort scratch: cell hashes", sort_scratch(triangles, sizeof(cl_uint), sizeof(cl_uint)), L::Detection)
      .add("sort scratch: couples", sort_scratch(capacity, sizeof(cl_ulong), 0), L::Scratch);
  return p;
}

ContactDetection::ContactDetection(ClContext& cl, DeviceArrays& a, double skin, size_t initial_capacity,
                                   const std::vector<std::array<int, 2>>& bonds, const std::vector<char>& owned_first)
    : cl_(cl), count_(a.num_triangles) {
  const size_t group = cl.group_size();
  if (group == 0 || (group & (group - 1)) != 0)
    throw DeviceError("contact detection needs a power-of-two work-group size, not " + std::to_string(group));
  if (count_ > 0xffffffffu) throw DeviceError("contact detection: more than 2^32 triangles");
  groups_ = (count_ + group - 1) / group;
  max_cells_ = cell_limit(count_);
  capacity_ = first_capacity(count_, initial_capacity);

  const size_t n = std::max<size_t>(count_, 1);
  const MemoryPlan arrays = plan(count_, group, initial_capacity, !bonds.empty(), !owned_first.empty());
  detection_arrays_ = arrays;
  partial_bounds_ = arrays.allocate(cl, "contact partial bounds");
  partial_side_ = arrays.allocate(cl, "contact partial sides");
  grid_ = arrays.allocate(cl, "contact grid");
  dims_ = arrays.allocate(cl, "contact grid size");
    active_ = arrays.allocate(cl, "contact active mask");
  counter_ = arrays.allocate(cl, "contact couple counter");
  keys_ = arrays.allocate(cl, "contact couples");
  upload(cl, active_, std::vector<cl_uint>(count_, 1u));
  if (!bonds.empty()) {
    std::vector<cl_uint> partners(3 * n, kNoPartner);
    for (const auto& b : bonds)
      for (int side = 0; side < 2; ++side) {
        const size_t t = static_cast<size_t>(b[side]);
        cl_uint* slot = &partners[3 * t];
        int k = 0;
        while (k < 3 && slot[k] != kNoPartner) ++k;
        if (t >= count_ || k == 3)
          throw InputError("contact detection: triangle " + std::to_string(t) + " is not in the mesh or has more than three CE4s");
        slot[k] = static_cast<cl_uint>(b[1 - side]);
      }
    bond_partners_ = arrays.allocate(cl, "contact bond partners");
    upload(cl, bond_partners_, partners);
  }
  // A defined grid before the first run (origin 0, unit cell, one cell).
  upload(cl, grid_, std::vector<real4>{real4{0, 0, 1, 0}});
  upload(cl, dims_, std::vector<cl_uint>{1, 1, 1, 0});

  std::map<std::string, std::string> defines{{"GROUP_SIZE", std::to_string(group)},
                                                            {"NO_PARTNER", std::to_string(kNoPartner) + "u"},
                                                            {"SMALL_SORT", std::to_string(kSmallSort)}};
  if (!bonds.empty()) defines["BONDED_PAIRS"] = "1";
  if (!owned_first.empty()) {
    if (owned_first.size() != count_) throw DeviceError("contact detection: the owned-triangle mask has the wrong size");
    defines["OWNED_FIRST"] = "1";
    owned_first_ = arrays.allocate(cl, "contact owned triangles");
    upload(cl, owned_first_, std::vector<cl_uchar>(owned_first.begin(), owned_first.end()));
  }
  const auto program = cl.build(kernel_source::contact_detection, defines);
  const cl_uint nt = static_cast<cl_uint>(count_);

  boxes_kernel_ = compute::kernel(program, "triangle_boxes");
  {
    KernelArgs k(boxes_kernel_);
    k("n_triangles", nt)("tri_nodes", a.tri_nodes)("position", a.position)("half_skin", static_cast<real>(0.5 * skin));
    bind_later(k, "boxes", kBoxes);
    k("partial_bounds", partial_bounds_)("partial_side", partial_side_).done();
  }

  grid_kernel_ = compute::kernel(program, "grid_setup");
  bind_args(grid_kernel_)("n_groups", static_cast<cl_uint>(groups_))("partial_bounds", partial_bounds_)(
      "partial_side", partial_side_)("max_cells", static_cast<cl_uint>(max_cells_))("grid", grid_)("dims", dims_)
      .done();

  clear_kernel_ = compute::kernel(program, "clear_cells");
  {
    KernelArgs k(clear_kernel_);
    k("max_cells", static_cast<cl_uint>(max_cells_));
    bind_later(k, "cell_first", kCellFirst);
    bind_later(k, "cell_last", kCellLast);
    k.done();
  }

  hash_kernel_ = compute::kernel(program, "cell_hash");
  {
    KernelArgs k(hash_kernel_);
    k("n_triangles", nt);
    bind_later(k, "boxes", kBoxes);
    k("grid", grid_)("dims", dims_);
    bind_later(k, "hash", kHash);
    bind_later(k, "tri", kTri);
    k.done();
  }

  range_kernel_ = compute::kernel(program, "cell_range");
  {
    KernelArgs k(range_kernel_);
    k("n_triangles", nt);
    bind_later(k, "sorted_hash", kHash);
    bind_later(k, "cell_first", kCellFirst);
    bind_later(k, "cell_last", kCellLast);
    k.done();
  }

  small_pairs_kernel_ = compute::kernel(program, "sort_small_pairs");
  {
    KernelArgs k(small_pairs_kernel_);
    k("n", nt);
    bind_later(k, "hash", kHash);
    bind_later(k, "tri", kTri);
    k.done();
  }
  small_keys_kernel_ = compute::kernel(program, "sort_small_keys");
  {
    KernelArgs k(small_keys_kernel_);
    small_keys_count_ = k.later("n", cl_uint(0));
    small_keys_keys_ = k.later("keys", keys_);
    k.done();
  }

  couples_kernel_ = compute::kernel(program, "find_couples");
  KernelArgs couples(couples_kernel_);
  couples("n_triangles", nt)("tri_nodes", a.tri_nodes);
  bind_later(couples, "boxes", kBoxes);
  couples("active", active_)("grid", grid_)("dims", dims_);
  bind_later(couples, "cell_first", kCellFirst);
  bind_later(couples, "cell_last", kCellLast);
  bind_later(couples, "sorted_tri", kTri);
  couples_capacity_ = couples.later("capacity", static_cast<cl_uint>(std::min<size_t>(capacity_, 0xffffffffu)));
  couples("count", counter_);
  couples_keys_ = couples.later("keys", keys_);
  if (!bonds.empty()) couples("bond_partners", bond_partners_);
  if (!owned_first.empty()) couples("owned_first", owned_first_);
  couples.done();
}

void ContactDetection::grow(size_t needed) {
  const size_t capacity = grown(needed);
  keys_ = couple_list(capacity).allocate(cl_, "contact couples");
  capacity_ = capacity;
  couples_capacity_.set(static_cast<cl_uint>(std::min<size_t>(capacity_, 0xffffffffu)));
  couples_keys_.set(keys_);
}

void ContactDetection::find_couples() {
  const cl_uint zero = 0;
  try {
    cl_.queue().enqueue_fill_buffer(counter_, &zero, sizeof(zero), 0, sizeof(zero));
  } catch (const compute::opencl_error& e) {
    throw DeviceError(std::string("contact detection: clearing the couple counter failed: ") + e.what());
  }
  cl_.enqueue(couples_kernel_, count_);
}

void ContactDetection::bind_later(KernelArgs& args, const char* name, int array) {
  detection_args_.push_back({array, args.later(name, counter_)});  // the counter until run() binds the array
}

void ContactDetection::hold_arrays(bool on) {
  static const char* const names[kDetectionArrays] = {"contact boxes", "contact cell first", "contact cell last",
                                                      "contact hashes", "contact sorted triangles"};
  compute::buffer* held[kDetectionArrays] = {&boxes_, &cell_first_, &cell_last_, &hash_, &tri_};
  for (int k = 0; k < kDetectionArrays; ++k)
    *held[k] = on ? detection_arrays_.allocate(cl_, names[k]) : compute::buffer();
  for (auto& [array, arg] : detection_args_) arg.set(on ? *held[array] : counter_);
}

size_t ContactDetection::run() {
  last_count_ = 0;
  if (count_ == 0) return 0;
  auto& queue = cl_.queue();
  // Boxes, cells, hashes: for this detection only (released once the count is read; the
  // count's read waits for every kernel that used them).
  hold_arrays(true);
  struct Release {
    ContactDetection& d;
    ~Release() {
      try {
        d.hold_arrays(false);
      } catch (...) {  // unwinding from a failed detection: the arrays go with the stage
      }
    }
  } release{*this};

  // 1. Boxes and the grid around them.
  cl_.enqueue(boxes_kernel_, count_);
  cl_.enqueue(grid_kernel_, cl_.group_size());  // one work-group
  cl_.enqueue(clear_kernel_, max_cells_);
  // 2-4. Hash, sort (hash, triangle), cell ranges.
  cl_.enqueue(hash_kernel_, count_);
  try {
    if (force_radix_)
      compute::detail::radix_sort_by_key(at<cl_uint>(hash_, 0), at<cl_uint>(hash_, count_), at<cl_uint>(tri_, 0), queue);
    else if (count_ <= kSmallSort)
      cl_.enqueue(small_pairs_kernel_, cl_.group_size());  // one work-group
    else
      compute::sort_by_key(at<cl_uint>(hash_, 0), at<cl_uint>(hash_, count_), at<cl_uint>(tri_, 0), queue);
  } catch (const compute::opencl_error& e) {
    throw DeviceError(std::string("contact detection: sorting the cell hashes failed: ") + e.what());
  }
  cl_.enqueue(range_kernel_, count_);

  // 5. Couples; on overflow grow to the exact count (×1.5) and scan again.
  find_couples();
  size_t found = download<cl_uint>(cl_, counter_, 1)[0];
  if (found > capacity_) {
    grow(found);
    find_couples();
    found = download<cl_uint>(cl_, counter_, 1)[0];
    if (found > capacity_)  // the scan is deterministic in its count; this cannot happen
      throw DeviceError("contact detection: couple count changed between two scans");
  }
  hold_arrays(false);  // before the couples' sort takes its scratch

  // 6. Canonical order.
  if (found > 1) {
    try {
      if (force_radix_) {
        compute::detail::radix_sort(at<cl_ulong>(keys_, 0), at<cl_ulong>(keys_, found), queue);
      } else if (found <= kSmallSort) {
        small_keys_count_.set(static_cast<cl_uint>(found));
        small_keys_keys_.set(keys_);
        cl_.enqueue(small_keys_kernel_, cl_.group_size());  // one work-group
      } else {
        compute::sort(at<cl_ulong>(keys_, 0), at<cl_ulong>(keys_, found), queue);
      }
    } catch (const compute::opencl_error& e) {
      throw DeviceError(std::string("contact detection: sorting the couples failed: ") + e.what());
    }
  }
  last_count_ = found;
  return found;
}

compute::buffer& ContactDetection::couple_keys() { return keys_; }
size_t ContactDetection::capacity() const { return capacity_; }
size_t ContactDetection::last_count() const { return last_count_; }

ContactDetection::Grid ContactDetection::grid() {
  const auto g = download<real4>(cl_, grid_, 1)[0];
  const auto d = download<cl_uint>(cl_, dims_, 4);
  return Grid{static_cast<double>(g.z), static_cast<double>(g.x), static_cast<double>(g.y), d[0], d[1]};
}

void ContactDetection::set_active(const std::vector<uint32_t>& active) {
  if (active.size() != count_)
    throw InputError("contact detection: active mask has " + std::to_string(active.size()) +
                     " entries for " + std::to_string(count_) + " triangles");
  upload(cl_, active_, active);
}

}  // namespace fdem
