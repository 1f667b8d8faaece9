#include "engine/stages/contact_detection.hpp"

#include <algorithm>
#include <map>
#include <boost/compute/exception.hpp>
#include <string>

#include "base/errors.hpp"
#include "engine/device/kernel_args.hpp"

namespace fdem {

namespace {

// Most grid cells a run may use: 2 per triangle + 1024 (the cells' starts are resident;
// the grids of the cases use 0.14 (the bench's UCS) to 0.66 (the blasting mesh, refined
// or not) cells a triangle, so the cap binds only where pieces fly far apart, and there
// the cells grow: session 25, docs/performance-notes.md).
size_t cell_limit(size_t triangles) { return 2 * triangles + 1024; }

// Blocks of the prefix sums (4 entries per work-item of a work-group).
size_t scan_blocks(size_t entries, size_t group_size) { return std::max<size_t>(1, (entries + 4 * group_size - 1) / (4 * group_size)); }

}  // namespace

MemoryPlan ContactDetection::cell_entries(size_t capacity) {
  return MemoryPlan().add("contact cell entries", std::max<size_t>(capacity, 1) * sizeof(cl_uint));
}

MemoryPlan ContactDetection::couple_list(size_t capacity) {
  return MemoryPlan().add("contact couples", capacity * sizeof(cl_ulong));
}

MemoryPlan ContactDetection::plan(size_t triangles, size_t group_size, size_t initial_capacity, bool bonds,
                                  bool owned_first) {
  const size_t n = std::max<size_t>(triangles, 1), groups = std::max<size_t>(groups_for(triangles, group_size), 1);
  const size_t capacity = first_capacity(triangles, initial_capacity);
  MemoryPlan p;
  // Resident, so that a detection allocates nothing: the boxes, the cells' starts (one
  // more than the cells), the cells' entries (one per small triangle, one per covered
  // cell of a large one: grows when a detection finds more, like the couples), and one
  // uint per triangle (+1) for the couples' segment starts.
  p.add("contact boxes", n * sizeof(cl_float4))  // float, rounded outward (load_box)
      .add("contact partial bounds", groups * sizeof(real4))
      .add("contact partial sides", groups * sizeof(real2))
      .add("contact grid", sizeof(real4))
      .add("contact grid size", 4 * sizeof(cl_uint))
      .add("contact cell start", (cell_limit(triangles) + 1) * sizeof(cl_uint))
      .add(cell_entries(first_entries(triangles)))
      .add("contact triangle offsets", (n + 1) * sizeof(cl_uint))
      .add("contact scan blocks", scan_blocks(cell_limit(triangles) + 1, group_size) * sizeof(cl_uint))
      .add("contact active mask", n * sizeof(cl_uint))
      .add(couple_list(capacity));
  if (bonds) p.add("contact bond partners", 3 * n * sizeof(cl_uint));
  if (owned_first) p.add("contact owned triangles", n * sizeof(cl_uchar));
  return p;
}

ContactDetection::ContactDetection(ClContext& cl, DeviceArrays& a, double skin, size_t initial_capacity,
                                   const std::vector<std::array<int, 2>>& bonds, const std::vector<char>& owned_first,
                                   bool list_inactive)
    : cl_(cl), count_(a.num_triangles) {
  const size_t group = cl.group_size();
  if (group == 0 || (group & (group - 1)) != 0)
    throw DeviceError("contact detection needs a power-of-two work-group size, not " + std::to_string(group));
  if (count_ > 0xffffffffu) throw DeviceError("contact detection: more than 2^32 triangles");
  // A GPU walks a triangle's cells with nine work-items (a small triangle's 3x3: one cell
  // each), so that enough are in flight to hide the memory latency of the walks; a CPU
  // with one (its few threads gain nothing from more).
  parts_ = cl.info().is_gpu && count_ * 9 <= 0xffffffffu ? 9 : 1;
  groups_ = (count_ + group - 1) / group;
  max_cells_ = cell_limit(count_);
  capacity_ = first_capacity(count_, initial_capacity);

  const size_t n = std::max<size_t>(count_, 1);
  const MemoryPlan arrays = plan(count_, group, initial_capacity, !bonds.empty(), !owned_first.empty());
  boxes_ = arrays.allocate(cl, "contact boxes");
  partial_bounds_ = arrays.allocate(cl, "contact partial bounds");
  partial_side_ = arrays.allocate(cl, "contact partial sides");
  grid_ = arrays.allocate(cl, "contact grid");
  dims_ = arrays.allocate(cl, "contact grid size");
  cell_start_ = arrays.allocate(cl, "contact cell start");
  sorted_tri_ = arrays.allocate(cl, "contact cell entries");
  entries_capacity_ = std::max<size_t>(first_entries(count_), 1);
  offsets_ = arrays.allocate(cl, "contact triangle offsets");
  scan_blocks_ = arrays.allocate(cl, "contact scan blocks");
  active_ = arrays.allocate(cl, "contact active mask");
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
                                             {"NO_PARTNER", std::to_string(kNoPartner) + "u"}};
  if (!bonds.empty()) defines["BONDED_PAIRS"] = "1";
  if (list_inactive) defines["LIST_INACTIVE"] = "1";
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
    k("n_triangles", nt)("tri_nodes", a.tri_nodes);
    box_positions_ = k.later("position", a.position);
    half_skin_ = k.later("half_skin", static_cast<real>(0.5 * skin));
    k("boxes", boxes_)("partial_bounds", partial_bounds_)(
        "partial_side", partial_side_)
        .done();
  }
  positions_ = a.position;
  grid_kernel_ = compute::kernel(program, "grid_setup");
  bind_args(grid_kernel_)("n_groups", static_cast<cl_uint>(groups_))("partial_bounds", partial_bounds_)("partial_side", partial_side_)("max_cells", static_cast<cl_uint>(max_cells_))(
      "grid", grid_)("dims", dims_)
      .done();
  cell_count_kernel_ = compute::kernel(program, "cell_count");
  bind_args(cell_count_kernel_)("n_triangles", nt)("boxes", boxes_)("grid", grid_)("dims", dims_)(
      "cell_start", cell_start_)
      .done();
  cell_scatter_kernel_ = compute::kernel(program, "cell_scatter");
  {
    KernelArgs k(cell_scatter_kernel_);
    k("n_triangles", nt)("boxes", boxes_)("grid", grid_)("dims", dims_)("cell_start", cell_start_);
    scatter_capacity_ = k.later("capacity", static_cast<cl_uint>(entries_capacity_));
    scatter_entries_ = k.later("sorted_tri", sorted_tri_);
    k.done();
  }
  scan_blocks_kernel_ = compute::kernel(program, "scan_blocks");
  scan_sums_kernel_ = compute::kernel(program, "scan_block_sums");
  scan_add_kernel_ = compute::kernel(program, "scan_add");

  // The couple kernels serve detections (covered = kDetection) and extensions alike.
  auto couples_common = [&](compute::kernel& k, Couples& bound, bool write) {
    KernelArgs args(k);
    args("n_triangles", nt);
    bound.parts = args.later("parts", static_cast<cl_uint>(parts_));
    bound.covered = args.later("covered", kDetection);
    args("tri_nodes", a.tri_nodes)("boxes", boxes_)("active", active_)("grid", grid_)("dims", dims_)(
        "cell_start", cell_start_);
    bound.entries = args.later("sorted_tri", sorted_tri_);
    bound.n_entries = args.later("n_entries", static_cast<cl_uint>(std::min<size_t>(entries_capacity_, 0xffffffffu)));
    bound.position = args.later("position", a.position);
    bound.reach = args.later("reach", static_cast<real>(skin));
    args("couple_offset", offsets_);
    if (write) {
      bound.listed = args.later("listed", cl_uint(0));
      bound.keys = args.later("keys", keys_);
    }
    if (!bonds.empty()) args("bond_partners", bond_partners_);
    if (!owned_first.empty()) args("owned_first", owned_first_);
    args.done();
  };
  couple_count_kernel_ = compute::kernel(program, "couple_count");
  couples_common(couple_count_kernel_, count_args_, false);
  couple_write_kernel_ = compute::kernel(program, "couple_write");
  couples_common(couple_write_kernel_, write_args_, true);
  sort_kernel_ = compute::kernel(program, "sort_segments");
  {
    KernelArgs k(sort_kernel_);
    k("n_triangles", nt)("couple_offset", offsets_);
    sort_listed_ = k.later("listed", cl_uint(0));
    sort_keys_ = k.later("keys", keys_);
    k.done();
  }
  // Extensions by joined triangles: one rank only (a split run's couples are placed by
  // their rank in the whole sorted list; it detects again instead).
  split_ = !owned_first.empty();
}

void ContactDetection::grow(size_t needed) {
  const size_t capacity = grown(needed);
  keys_ = couple_list(capacity).allocate(cl_, "contact couples");
  capacity_ = capacity;
  write_args_.keys.set(keys_);
  sort_keys_.set(keys_);
}

void ContactDetection::set_parts(size_t parts) {
  if (parts == 0 || parts > 64) throw DeviceError("contact detection: " + std::to_string(parts) + " parts per triangle (1 to 64)");
  if (count_ * parts > 0xffffffffu) throw DeviceError("contact detection: too many work-items for the couple search");
  parts_ = parts;
  count_args_.parts.set(static_cast<cl_uint>(parts));
  write_args_.parts.set(static_cast<cl_uint>(parts));
}

void ContactDetection::exclusive_scan(const compute::buffer& data, size_t entries) {
  const size_t group = cl_.group_size(), blocks = scan_blocks(entries, group);
  const cl_uint n = static_cast<cl_uint>(entries);
  bind_args(scan_blocks_kernel_)("n", n)("data", data)("block_sums", scan_blocks_).done();
  cl_.enqueue(scan_blocks_kernel_, blocks * group);
  bind_args(scan_sums_kernel_)("n_blocks", static_cast<cl_uint>(blocks))("block_sums", scan_blocks_).done();
  cl_.enqueue(scan_sums_kernel_, group);  // one work-group
  bind_args(scan_add_kernel_)("n", n)("data", data)("block_sums", scan_blocks_).done();
  cl_.enqueue(scan_add_kernel_, entries);
}

void ContactDetection::bin_triangles(bool boxes) {
  const cl_uint zero = 0;
  if (boxes) {
    cl_.enqueue(boxes_kernel_, count_);
    cl_.enqueue(grid_kernel_, cl_.group_size());  // one work-group
  }
  cl_.queue().enqueue_fill_buffer(cell_start_, &zero, sizeof(zero), 0, (max_cells_ + 1) * sizeof(cl_uint));
  cl_.enqueue(cell_count_kernel_, count_);
  exclusive_scan(cell_start_, max_cells_ + 1);
  cl_.enqueue(cell_scatter_kernel_, count_);
}

void ContactDetection::count_couples(cl_uint covered) {
  count_args_.covered.set(covered);
  const cl_uint zero = 0;
  cl_.queue().enqueue_fill_buffer(offsets_, &zero, sizeof(zero), 0, (count_ + 1) * sizeof(cl_uint));
  cl_.enqueue(couple_count_kernel_, count_ * parts_);
  exclusive_scan(offsets_, count_ + 1);
}

std::array<size_t, 2> ContactDetection::read_totals() {
  // The entries' total is the last cell's end; the couples' the last segment start. Two
  // reads, one wait (the queue is in order).
  cl_uint entries = 0, couples = 0;
  cl_.queue().enqueue_read_buffer_async(cell_start_, max_cells_ * sizeof(cl_uint), sizeof(cl_uint), &entries);
  cl_.queue().enqueue_read_buffer(offsets_, count_ * sizeof(cl_uint), sizeof(cl_uint), &couples);
  return {entries, couples};
}

size_t ContactDetection::bin_and_count(bool boxes, cl_uint covered) {
  bin_triangles(boxes);
  count_couples(covered);
  auto totals = read_totals();
  if (totals[0] > entries_capacity_) {
    // More cell entries than the array holds (large triangles covering many cells): grow
    // to the total read and sort again (the boxes and the grid stand).
    entries_capacity_ = grown(totals[0]);
    sorted_tri_ = cell_entries(entries_capacity_).allocate(cl_, "contact cell entries");
    scatter_entries_.set(sorted_tri_);
    scatter_capacity_.set(static_cast<cl_uint>(std::min<size_t>(entries_capacity_, 0xffffffffu)));
    for (Couples* bound : {&count_args_, &write_args_}) {
      bound->entries.set(sorted_tri_);
      bound->n_entries.set(static_cast<cl_uint>(std::min<size_t>(entries_capacity_, 0xffffffffu)));
    }
    bin_triangles(false);
    count_couples(covered);
    totals = read_totals();
    if (totals[0] > entries_capacity_) throw DeviceError("contact detection: cell entry count changed between two sorts");
  }
  return totals[1];
}

void ContactDetection::write_couples(cl_uint covered, size_t listed) {
  write_args_.covered.set(covered);
  write_args_.listed.set(static_cast<cl_uint>(listed));
  cl_.enqueue(couple_write_kernel_, count_ * parts_);
  sort_listed_.set(static_cast<cl_uint>(listed));
  cl_.enqueue(sort_kernel_, count_);
}

void ContactDetection::bind_positions(const compute::buffer& positions) {
  box_positions_.set(positions);
  for (Couples* bound : {&count_args_, &write_args_}) bound->position.set(positions);
}

void ContactDetection::rebuild_grid(const compute::buffer& positions_at_run) {
  if (count_ == 0) return;
  bind_positions(positions_at_run);
  try {
    bin_and_count(true, kDetection);  // the couples' count is not used: the list is restored
  } catch (const compute::opencl_error& e) {
    bind_positions(positions_);
    throw DeviceError(std::string("contact detection: rebuilding the grid failed: ") + e.what());
  }
  bind_positions(positions_);
  can_extend_ = !split_ && stamp_loaded_;
}

size_t ContactDetection::extend_joined(size_t listed, size_t limit, cl_uint covered_to,
                                       const compute::buffer& positions_at_run) {
  if (!can_extend_ || count_ == 0) return 0;
  size_t added = 0;
  // The couple kernels test the gaps on the positions the boxes came from (the boxes'
  // kernel does not run in an extension).
  for (Couples* bound : {&count_args_, &write_args_}) bound->position.set(positions_at_run);
  struct Rebind {
    ContactDetection& stage;
    ~Rebind() { stage.bind_positions(stage.positions_); }
  } rebind{*this};
  try {
    count_couples(covered_);
    cl_uint total = 0;
    cl_.queue().enqueue_read_buffer(offsets_, count_ * sizeof(cl_uint), sizeof(cl_uint), &total);
    added = total;
    if (listed + added > limit) return 0;
    if (listed + added > capacity_) {  // grow, keeping the listed couples
      compute::buffer old = keys_;
      grow(listed + added);
      if (listed) cl_.queue().enqueue_copy_buffer(old, keys_, 0, 0, listed * sizeof(cl_ulong));
    }
    if (added > 0) write_couples(covered_, listed);
  } catch (const compute::opencl_error& e) {
    throw DeviceError(std::string("contact detection: extending the list by joined triangles failed: ") + e.what());
  }
  covered_ = std::max(covered_, covered_to);
  last_count_ = listed + added;
  return last_count_;
}

void ContactDetection::set_skin(double skin) {
  half_skin_.set(static_cast<real>(0.5 * skin));
  for (Couples* bound : {&count_args_, &write_args_}) bound->reach.set(static_cast<real>(skin));
}

size_t ContactDetection::run() {
  last_count_ = 0;
  if (count_ == 0) return 0;
  size_t found = 0;
  try {
    // Boxes, grid, triangles into cells, couples per triangle: one wait for the totals.
    found = bin_and_count(true, kDetection);
    if (found > capacity_) grow(found);
    // Each triangle writes and sorts its segment: the list in ascending key order.
    write_couples(kDetection, 0);
  } catch (const compute::opencl_error& e) {
    throw DeviceError(std::string("contact detection: ") + e.what());
  }
  last_count_ = found;
  can_extend_ = !split_;
  stamp_loaded_ = true;
  return found;
}

compute::buffer& ContactDetection::couple_keys() { return keys_; }
size_t ContactDetection::capacity() const { return capacity_; }
size_t ContactDetection::last_count() const { return last_count_; }

ContactDetection::Grid ContactDetection::grid() {
  const auto g = download<real4>(cl_, grid_, 1)[0];
  const auto d = download<cl_uint>(cl_, dims_, 4);
  return Grid{static_cast<double>(g.z), static_cast<double>(g.x), static_cast<double>(g.y), d[0], d[1], static_cast<double>(g.w)};
}

void ContactDetection::set_active(const std::vector<uint32_t>& active) {
  if (active.size() != count_)
    throw InputError("contact detection: active mask has " + std::to_string(active.size()) +
                     " entries for " + std::to_string(count_) + " triangles");
  upload(cl_, active_, active);
}

bool ContactDetection::restore_list(StateReader& in) {
  if (split_) return false;
  const size_t listed = static_cast<size_t>(in.integer("contact_couples"));
  if (listed > capacity_) grow(listed);
  in.buffer<cl_ulong>("contact_keys", keys_, listed);
  last_count_ = listed;
  return true;
}

void ContactDetection::save_state(StateWriter& out) const {
  out.buffer<cl_uint>("contact_active", active_, count_);
  const cl_long covered = covered_;
  out.host<cl_long>("contact_covered_stamp", &covered, 1);
}

void ContactDetection::load_state(StateReader& in) {
  in.buffer<cl_uint>("contact_active", active_, count_);
  // A checkpoint written before lists were extended has no stamp: no extension until the
  // next run() (an extension needs to know which joins the list holds).
  stamp_loaded_ = in.has("contact_covered_stamp");
  cl_long covered = 0;
  if (stamp_loaded_) in.host<cl_long>("contact_covered_stamp", &covered, 1);
  covered_ = static_cast<cl_uint>(covered);
  can_extend_ = false;  // until rebuild_grid (the Solver calls it with the skin's positions)
}

}  // namespace fdem
