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

namespace fdem {

namespace {

template <typename T>
compute::buffer_iterator<T> at(const compute::buffer& b, size_t i) {
  return compute::make_buffer_iterator<T>(b, i);
}

}  // namespace

ContactDetection::ContactDetection(ClContext& cl, DeviceArrays& a, double skin, size_t initial_capacity,
                                   const std::vector<std::array<int, 2>>& bonds)
    : cl_(cl), count_(a.num_triangles) {
  const size_t group = cl.group_size();
  if (group == 0 || (group & (group - 1)) != 0)
    throw DeviceError("contact detection needs a power-of-two work-group size, not " + std::to_string(group));
  if (count_ > 0xffffffffu) throw DeviceError("contact detection: more than 2^32 triangles");
  groups_ = (count_ + group - 1) / group;
  max_cells_ = 4 * count_ + 1024;
  capacity_ = initial_capacity ? initial_capacity : std::max<size_t>(8 * count_, 1);

  const size_t n = std::max<size_t>(count_, 1);
  boxes_ = cl.allocate(n * sizeof(real4), "contact boxes");
  partial_bounds_ = cl.allocate(std::max<size_t>(groups_, 1) * sizeof(real4), "contact partial bounds");
  partial_side_ = cl.allocate(std::max<size_t>(groups_, 1) * sizeof(real), "contact partial sides");
  grid_ = cl.allocate(sizeof(real4), "contact grid");
  dims_ = cl.allocate(4 * sizeof(cl_uint), "contact grid size");
  cell_first_ = cl.allocate(max_cells_ * sizeof(cl_uint), "contact cell first");
  cell_last_ = cl.allocate(max_cells_ * sizeof(cl_uint), "contact cell last");
  hash_ = cl.allocate(n * sizeof(cl_uint), "contact hashes");
  tri_ = cl.allocate(n * sizeof(cl_uint), "contact sorted triangles");
  active_ = cl.allocate(n * sizeof(cl_uint), "contact active mask");
  counter_ = cl.allocate(sizeof(cl_uint), "contact couple counter");
  keys_ = cl.allocate(capacity_ * sizeof(cl_ulong), "contact couples");
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
    bond_partners_ = cl.allocate(partners.size() * sizeof(cl_uint), "contact bond partners");
    upload(cl, bond_partners_, partners);
  } else {
    bond_partners_ = cl.allocate(sizeof(cl_uint), "contact bond partners (none)");
  }
  // A defined grid before the first run (origin 0, unit cell, one cell).
  upload(cl, grid_, std::vector<real4>{real4{0, 0, 1, 0}});
  upload(cl, dims_, std::vector<cl_uint>{1, 1, 1, 0});

  std::map<std::string, std::string> defines{{"GROUP_SIZE", std::to_string(group)},
                                                            {"NO_PARTNER", std::to_string(kNoPartner) + "u"}};
  if (!bonds.empty()) defines["BONDED_PAIRS"] = "1";
  const auto program = cl.build("contact_detection", defines);
  const cl_uint nt = static_cast<cl_uint>(count_);

  boxes_kernel_ = compute::kernel(program, "triangle_boxes");
  boxes_kernel_.set_arg(0, nt);
  boxes_kernel_.set_arg(1, a.tri_nodes);
  boxes_kernel_.set_arg(2, a.position);
  boxes_kernel_.set_arg(3, static_cast<real>(0.5 * skin));
  boxes_kernel_.set_arg(4, boxes_);
  boxes_kernel_.set_arg(5, partial_bounds_);
  boxes_kernel_.set_arg(6, partial_side_);

  grid_kernel_ = compute::kernel(program, "grid_setup");
  grid_kernel_.set_arg(0, static_cast<cl_uint>(groups_));
  grid_kernel_.set_arg(1, partial_bounds_);
  grid_kernel_.set_arg(2, partial_side_);
  grid_kernel_.set_arg(3, static_cast<cl_uint>(max_cells_));
  grid_kernel_.set_arg(4, grid_);
  grid_kernel_.set_arg(5, dims_);

  clear_kernel_ = compute::kernel(program, "clear_cells");
  clear_kernel_.set_arg(0, static_cast<cl_uint>(max_cells_));
  clear_kernel_.set_arg(1, cell_first_);
  clear_kernel_.set_arg(2, cell_last_);

  hash_kernel_ = compute::kernel(program, "cell_hash");
  hash_kernel_.set_arg(0, nt);
  hash_kernel_.set_arg(1, boxes_);
  hash_kernel_.set_arg(2, grid_);
  hash_kernel_.set_arg(3, dims_);
  hash_kernel_.set_arg(4, hash_);
  hash_kernel_.set_arg(5, tri_);

  range_kernel_ = compute::kernel(program, "cell_range");
  range_kernel_.set_arg(0, nt);
  range_kernel_.set_arg(1, hash_);
  range_kernel_.set_arg(2, cell_first_);
  range_kernel_.set_arg(3, cell_last_);

  couples_kernel_ = compute::kernel(program, "find_couples");
  couples_kernel_.set_arg(0, nt);
  couples_kernel_.set_arg(1, a.tri_nodes);
  couples_kernel_.set_arg(2, boxes_);
  couples_kernel_.set_arg(3, active_);
  couples_kernel_.set_arg(4, grid_);
  couples_kernel_.set_arg(5, dims_);
  couples_kernel_.set_arg(6, cell_first_);
  couples_kernel_.set_arg(7, cell_last_);
  couples_kernel_.set_arg(8, tri_);
  couples_kernel_.set_arg(9, static_cast<cl_uint>(std::min<size_t>(capacity_, 0xffffffffu)));
  couples_kernel_.set_arg(10, counter_);
  couples_kernel_.set_arg(11, keys_);
  couples_kernel_.set_arg(12, bond_partners_);
}

void ContactDetection::grow(size_t needed) {
  const size_t capacity = needed + (needed + 1) / 2;  // ×1.5, rounded up
  keys_ = cl_.allocate(capacity * sizeof(cl_ulong), "contact couples");
  capacity_ = capacity;
  couples_kernel_.set_arg(9, static_cast<cl_uint>(std::min<size_t>(capacity_, 0xffffffffu)));
  couples_kernel_.set_arg(11, keys_);
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

size_t ContactDetection::run() {
  last_count_ = 0;
  if (count_ == 0) return 0;
  auto& queue = cl_.queue();

  // 1. Boxes and the grid around them.
  cl_.enqueue(boxes_kernel_, count_);
  cl_.enqueue(grid_kernel_, cl_.group_size());  // one work-group
  cl_.enqueue(clear_kernel_, max_cells_);
  // 2-4. Hash, sort (hash, triangle), cell ranges.
  cl_.enqueue(hash_kernel_, count_);
  try {
    if (force_radix_)
      compute::detail::radix_sort_by_key(at<cl_uint>(hash_, 0), at<cl_uint>(hash_, count_), at<cl_uint>(tri_, 0), queue);
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

  // 6. Canonical order.
  if (found > 1) {
    try {
      if (force_radix_)
        compute::detail::radix_sort(at<cl_ulong>(keys_, 0), at<cl_ulong>(keys_, found), queue);
      else
        compute::sort(at<cl_ulong>(keys_, 0), at<cl_ulong>(keys_, found), queue);
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
