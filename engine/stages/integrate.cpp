#include "engine/stages/integrate.hpp"

#include "engine/stages/node_gather.hpp"
#include "base/errors.hpp"

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace fdem {

Integrate::WorkRows Integrate::work_rows(const std::vector<uint32_t>& node_group, size_t groups, double local_damping) {
  WorkRows w{false, node_group.size()};
  if (local_damping != 0 || groups > 256) return w;
  const size_t moving = static_cast<size_t>(std::count_if(node_group.begin(), node_group.end(), [](uint32_t g) { return g != 0; }));
  if (moving >= (size_t(1) << 24)) return w;
  return WorkRows{true, moving};
}

MemoryPlan Integrate::plan(size_t nodes, size_t group_size, bool account_work, bool node_rows, size_t work_rows) {
  const size_t groups = std::max<size_t>(1, groups_for(nodes, Integrate::group_size(group_size)));
  MemoryPlan p;
  p.add("integrate group_work", groups * sizeof(real2))
      .add("integrate group_row", groups * sizeof(real4))
      .add("integrate node_work", (account_work ? std::max<size_t>(1, work_rows) : 1) * sizeof(real2));
  // The energy rows' per-node values: only a split run keeps them (keep_energy_rows, for
  // energy()'s gather); one rank's kernel sums them into the partials itself.
  if (node_rows) p.add("integrate node_energy", std::max<size_t>(1, nodes) * sizeof(real4));
  return p.add("integrate node_energy placeholder", sizeof(real4))
      .add("integrate energy partials", 4 * std::max<size_t>(1, groups_for(nodes, kOrderedBlock)) * sizeof(real));
}

Integrate::Integrate(ClContext& cl, DeviceArrays& a, std::array<double, 2> gravity, double local_damping, double dt,
                     bool prescribed, bool account, ContactSkin* skin, std::optional<Gather> gather)
    : cl_(cl), count_(a.num_nodes), groups_(groups_for(a.num_nodes, group_size(cl.group_size()))),
      account_work_(accounts_work(prescribed, local_damping, account)), skin_test_(skin != nullptr) {
  local_ = group_size(cl.group_size());
  std::map<std::string, std::string> defines{{"GROUP_SIZE", std::to_string(local_)},
                                             {"SKIN_TEST", skin_test_ ? "1" : "0"}};
  // A split run: the skin test takes the nodes this rank owns only (ghosts are integrated
  // with a part of their forces before the exchange overwrites them).
  if (skin && skin->owned_mask()) defines["SKIN_OWNED"] = "1";
  defines["ORDERED_BLOCK"] = std::to_string(kOrderedBlock);
  gathers_ = gather.has_value();
  defines["GATHER_IN_STEP"] = gather ? "1" : "0";
  defines["MASS_SCALING"] = a.mass_scaling ? "1" : "0";
  // The work rows (work_rows): by group, the device's node_group words gain each moving
  // node's row above the group's 8 bits. (Only read when the work is accounted.)
  if (account_work_) {
    const size_t group_count = a.group_table.size() / sizeof(real4);
    auto node_group = download<cl_uint>(cl, a.node_group, count_);
    work_rows_ = work_rows(std::vector<uint32_t>(node_group.begin(), node_group.end()), group_count, local_damping);
    if (work_rows_.by_group) {
      for (size_t n = 0; n < count_; ++n) {
        if (node_group[n] == 0) continue;
        // The group's bits (a word packed by an earlier stage on these arrays keeps them).
        node_group[n] = (node_group[n] & 0xffu) | static_cast<cl_uint>(row_node_.size()) << 8;
        row_node_.push_back(static_cast<cl_uint>(n));
      }
      upload(cl, a.node_group, node_group);
    }
  }
  defines["WORK_ROWS_BY_GROUP"] = work_rows_.by_group ? "1" : "0";
  // The gravity potential of the energy rows reads the reference positions, which the
  // device holds only in a model with gravity (DeviceArrays); without, every node's term
  // is -m g·(x - X) = ±0 and the rows' ordered block sums (which start from +0) are +0
  // either way, so the kernel adds +0 without reading X.
  needs_reference_ = gravity[0] != 0.0 || gravity[1] != 0.0;
  has_reference_ = a.ref_position.get() != nullptr;
  defines["GRAVITY_POTENTIAL"] = has_reference_ ? "1" : "0";
  std::vector<const KernelSource*> libraries;
  if (gather) {
    for (const auto& d : NodeGather::force_defines(a, gather->ce4_slots, gather->contact_force_scale, gather->fluid_slots)) defines.insert(d);
    libraries.push_back(&kernel_source::node_gather);
  }
  // NVIDIA: 68 registers a work-item fit three work-groups of 256 per SM, 64 four. H200,
  // 1.08M TRI3: 0.159 → 0.139 ms a step (docs/performance-notes.md, session 7).
  const auto program = cl.build(kernel_source::integrate, defines, libraries, 64);
  kernel_ = compute::kernel(program, "integrate");
  const MemoryPlan arrays = plan(count_, cl.group_size(), account_work_, true, work_rows_.rows);
  group_work_ = arrays.allocate(cl, "integrate group_work");
  group_row_ = arrays.allocate(cl, "integrate group_row");
  upload(cl, group_work_, std::vector<real2>(std::max<size_t>(1, groups_)));
  upload(cl, group_row_, std::vector<real4>(std::max<size_t>(1, groups_)));
  const size_t work_items = account_work_ ? std::max<size_t>(1, work_rows_.rows) : 1;
  node_work_ = arrays.allocate(cl, "integrate node_work");
  upload(cl, node_work_, std::vector<real2>(work_items));
  node_energy_bytes_ = arrays.bytes("integrate node_energy");  // allocated by keep_energy_rows only
  placeholder_ = arrays.allocate(cl, "integrate node_energy placeholder");
  upload(cl, placeholder_, std::vector<real4>(1));
  partials_ = arrays.allocate(cl, "integrate energy partials");
  // Written on energy rows only: zero until the first, so a total read before it is 0.
  upload(cl, partials_, std::vector<real>(partials_.size() / sizeof(real)));
  KernelArgs args(kernel_);
  args("n_nodes", static_cast<cl_uint>(count_));
  if (gather)
    NodeGather::bind_force_sources(args, a, gather->ce4_slots, gather->contact_force_scale, gather->fluid_slots,
                                   gather->fluid_nodes);
  args("position", a.position)("velocity", a.velocity)(
      "node_force", a.node_force)("node_mass", a.node_mass)("bc_group", a.node_group)("bc_table", a.group_table)(
      "gx", static_cast<real>(gravity[0]))("gy", static_cast<real>(gravity[1]))(
      "local_damping", static_cast<real>(local_damping))("dt", static_cast<real>(dt));
  time_after_ = args.later("time_after", real(0));
  step_ = args.later("step", cl_int(0));
  args("conditions", a.conditions);
  if (skin) {
    args("position_at_build", skin->position_at_build())("monitor", skin->ring().buffer());
    if (skin->owned_mask()) args("node_owned", *skin->owned_mask());
    slot_ = args.later("slot", cl_uint(0));
    next_slot_ = args.later("next_slot", cl_uint(0));
  }
  args("ref_position", has_reference_ ? a.ref_position : a.position)("account_work", cl_int(account_work_ ? 1 : 0));
  energy_row_ = args.later("energy_row", cl_int(0));
  args("group_work", group_work_)("group_row", group_row_)("node_work", node_work_);
  node_rows_ = args.later("node_rows", cl_int(0));
  node_energy_arg_ = args.later("node_energy", placeholder_);
  args("energy_partials", partials_);
  args.done();
}

void Integrate::save_state(StateWriter& out) const {
  out.group_slots("integrate_work", group_work_, groups_, 2);
  if (!account_work_) return;
  if (!work_rows_.by_group) {
    out.buffer<real>("integrate_node_work", node_work_, count_, 2);
    return;
  }
  const auto rows = download<real2>(cl_, node_work_, row_node_.size());
  std::vector<real> per_node(2 * count_, real(0));
  for (size_t r = 0; r < row_node_.size(); ++r) per_node[2 * row_node_[r]] = rows[r].x, per_node[2 * row_node_[r] + 1] = rows[r].y;
  out.host<real>("integrate_node_work", per_node.data(), count_, 2);
}

void Integrate::load_state(StateReader& in) {
  in.group_slots("integrate_work", group_work_, groups_, 2);
  if (!account_work_) return;
  if (!work_rows_.by_group) {
    in.buffer<real>("integrate_node_work", node_work_, count_, 2);
    return;
  }
  std::vector<real> per_node(2 * count_);
  in.host<real>("integrate_node_work", per_node.data(), count_, 2);
  std::vector<real2> rows(std::max<size_t>(1, row_node_.size()), real2{0, 0});
  for (size_t r = 0; r < row_node_.size(); ++r) rows[r] = real2{per_node[2 * row_node_[r]], per_node[2 * row_node_[r] + 1]};
  // A free node's total is +0 (no row): a file with another value there was not written
  // by this model's run.
  for (size_t n = 0, r = 0; n < count_; ++n) {
    if (r < row_node_.size() && row_node_[r] == n) {
      ++r;
      continue;
    }
    if (per_node[2 * n] != real(0) || per_node[2 * n + 1] != real(0))
      throw InputError("checkpoint: integrate_node_work has work at node " + std::to_string(n) +
                       ", which has no prescribed motion and no local damping in this case");
  }
  upload(cl_, node_work_, rows);
}

void Integrate::keep_energy_rows() {
  if (keep_rows_) return;
  keep_rows_ = true;
  node_energy_ = cl_.allocate(node_energy_bytes_, "integrate node_energy");
  upload(cl_, node_energy_, std::vector<real4>(std::max<size_t>(1, count_)));  // zero until the first row
  node_energy_arg_.set(node_energy_);
  node_rows_.set(1);
}

void Integrate::enqueue(double time_after, int step, bool energy_row) {
  time_after_.set(static_cast<real>(time_after));
  step_.set(step);
  energy_row_.set(energy_row ? 1 : 0);
  // The kernel takes the row's ordered block sums itself (the rule of
  // engine/energy/energy.hpp); a split run also keeps the per-node values for the gather
  // of energy().
  if (energy_row && needs_reference_ && !has_reference_)
    throw DeviceError("integrate: an energy row with gravity needs the reference positions on the device, which "
                      "DeviceArrays keeps only for a model with gravity");
  if (skin_test_) {
    slot_.set(MonitorRing::slot_of(step + 1));
    next_slot_.set(MonitorRing::slot_of(step + 2));
  }
  cl_.enqueue(kernel_, count_, local_);
}

EnergyPart Integrate::queue_energy(const ItemSums& sums, RowReads* reads) {
  // Per node, in node order by the fixed rule (rank-independent): the kernel wrote
  // (kinetic, gravity potential, damping work and reaction work up to t) on the energy row.
  PendingSums pending;
  if (keep_rows_) {
    pending = sums(cl_, node_energy_, count_, 4, 0, 4, ItemKind::Node);
  } else {
    // The blocks' sums of the last energy row, added in block order (as OrderedSums does).
    const size_t blocks = groups_for(count_, kOrderedBlock);
    const size_t words = 4 * std::max<size_t>(1, blocks);
    std::function<std::vector<real>()> partial;
    if (reads) {
      partial = reads->read<real>(partials_, words);
    } else {
      auto now = download<real>(cl_, partials_, words);
      partial = [now] { return now; };
    }
    pending = [partial, blocks] {
      const auto values = partial();
      std::vector<double> sum(4, 0.0);
      for (size_t b = 0; b < blocks; ++b)
        for (int c = 0; c < 4; ++c) sum[c] += static_cast<double>(values[4 * b + c]);
      return sum;
    };
  }
  const bool account_work = account_work_;
  return [pending, account_work](EnergyTotals& e) {
    const auto sum = pending();
    e.kinetic += sum[0];
    e.gravity_potential += sum[1];
    if (!account_work) return;
    e.local_damping += -sum[2];
    e.boundary_work += sum[3];
  };
}

}  // namespace fdem
