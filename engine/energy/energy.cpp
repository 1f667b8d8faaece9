#include "engine/energy/energy.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/parallel/transport.hpp"

namespace fdem {

void EnergyBalance::start(const EnergyTotals& initial) {
  started_ = true;
  initial_stored_ = initial.stored();
  peak_kinetic_ = std::max(0.0, initial.kinetic);
}

double EnergyBalance::error(const EnergyTotals& now) {
  peak_kinetic_ = std::max(peak_kinetic_, now.kinetic);
  // Gravity's work so far is minus its potential: LS-DYNA books it as external work.
  const double scale = std::max({std::fabs(now.supplied()), std::fabs(initial_stored_), peak_kinetic_,
                                 std::fabs(now.gravity_potential), now.resolution});
  const double residual = now.stored() + now.dissipated() - now.supplied() - initial_stored_;
  return scale > 0 ? residual / scale : 0.0;
}

double EnergyBalance::ratio(const EnergyTotals& now) const {
  const double in = initial_stored_ + now.supplied();
  return in != 0 ? (now.stored() + now.dissipated()) / in : 1.0;
}

std::string EnergyBalance::largest_change(const EnergyTotals& a, const EnergyTotals& b) {
  const std::pair<const char*, double> changes[] = {
      {"kinetic_energy", b.kinetic - a.kinetic},
      {"strain_energy", b.strain - a.strain},
      {"cohesive_stored_energy", b.cohesive_stored - a.cohesive_stored},
      {"contact_stored_energy", b.contact_stored - a.contact_stored},
      {"gravity_potential", b.gravity_potential - a.gravity_potential},
      {"viscous_dissipation", b.viscous - a.viscous},
      {"local_damping_dissipation", b.local_damping - a.local_damping},
      {"friction_dissipation", b.friction - a.friction},
      {"contact_damping_dissipation", b.contact_damping - a.contact_damping},
      {"fracture_dissipation", b.fracture - a.fracture},
      {"absorbed_energy", b.absorbed - a.absorbed},
      {"excavated_energy", b.excavated - a.excavated},
      {"boundary_work", b.boundary_work - a.boundary_work},
      {"load_work", b.load_work - a.load_work},
      {"fluid_stored_energy", b.fluid_stored - a.fluid_stored},
      {"fluid_viscous_dissipation", b.fluid_viscous - a.fluid_viscous},
      {"fluid_injection_work", b.fluid_injection - a.fluid_injection},
      {"fluid_leak_off_energy", b.fluid_leak_off - a.fluid_leak_off}};
  const auto* best = &changes[0];
  for (const auto& c : changes)
    if (std::fabs(c.second) > std::fabs(best->second)) best = &c;
  return best->first;
}

std::array<double, 4> sum_group_slots(ClContext& cl, const compute::buffer& slots, std::size_t groups, int width) {
  std::array<double, 4> total = {0, 0, 0, 0};
  if (groups == 0) return total;
  const auto values = download<real>(cl, slots, groups * static_cast<std::size_t>(width));
  for (std::size_t g = 0; g < groups; ++g)
    for (int k = 0; k < width; ++k) total[k] += static_cast<double>(values[g * width + k]);
  return total;
}

}  // namespace fdem

namespace fdem {

std::vector<double> blocked_sums(const std::vector<real>& values, std::size_t count, int stride, int first, int width) {
  std::vector<double> total(static_cast<std::size_t>(width), 0.0);
  for (std::size_t begin = 0; begin < count; begin += kOrderedBlock) {
    const std::size_t end = std::min(count, begin + kOrderedBlock);
    for (int c = 0; c < width; ++c) {
      real s = 0;  // as the kernel: in `real`, left to right
      for (std::size_t i = begin; i < end; ++i) s += values[i * stride + first + c];
      total[c] += static_cast<double>(s);
    }
  }
  return total;
}

PendingSums all_items(ClContext& cl, const compute::buffer& values, std::size_t count, int stride, int first, int width,
                      ItemKind) {
  return sums_now(blocked_sums(download<real>(cl, values, count * stride), count, stride, first, width));
}

namespace {
// The rule's blocks of `count` items: how many, and the length of block b (the last may be short).
std::size_t block_count(std::size_t count) { return (count + kOrderedBlock - 1) / kOrderedBlock; }
std::size_t block_length(std::size_t count, std::size_t b) { return std::min(kOrderedBlock, count - b * kOrderedBlock); }
}  // namespace

BlockShare BlockShare::of(const std::vector<int>& global, const std::vector<char>& owned, std::size_t global_count) {
  // The owned items in global order (a local model keeps it, but the rule must not rely on it).
  std::vector<std::pair<int64_t, int>> mine;
  for (std::size_t i = 0; i < global.size(); ++i)
    if (owned[i]) mine.emplace_back(global[i], static_cast<int>(i));
  std::sort(mine.begin(), mine.end());
  std::vector<std::size_t> per_block(block_count(global_count), 0);
  for (const auto& m : mine) ++per_block.at(static_cast<std::size_t>(m.first) / kOrderedBlock);
  BlockShare share;
  share.global_count = global_count;
  for (const auto& m : mine) {
    const std::size_t b = static_cast<std::size_t>(m.first) / kOrderedBlock;
    if (per_block[b] == block_length(global_count, b)) {
      if (share.whole.empty() || share.whole.back() != static_cast<int64_t>(b)) share.whole.push_back(static_cast<int64_t>(b));
      share.whole_items.push_back(m.second);
    } else {
      share.shared.push_back(m.first);
      share.shared_items.push_back(m.second);
    }
  }
  return share;
}

namespace {
// BlockShare::message for a width known to the compiler (the copies of an item unroll).
template <int W>
void write_message(const BlockShare& share, const real* rows, int stride, int first, char* at) {
  constexpr std::size_t row = W * sizeof(real);
  std::size_t item = 0;
  for (const int64_t b : share.whole) {
    // As blocked_sums: from 0, left to right in `real`, each column on its own.
    real s[W] = {};
    for (std::size_t k = block_length(share.global_count, static_cast<std::size_t>(b)); k > 0; --k, ++item) {
      const real* v = rows + static_cast<std::size_t>(share.whole_items[item]) * stride + first;
      for (int c = 0; c < W; ++c) s[c] += v[c];
    }
    std::memcpy(at, s, row);
    at += row;
  }
  for (const int i : share.shared_items) {
    std::memcpy(at, rows + static_cast<std::size_t>(i) * stride + first, row);
    at += row;
  }
}
}  // namespace

void BlockShare::message(const real* rows, int stride, int first, int width, Bytes& out) const {
  out.resize((whole.size() + shared_items.size()) * width * sizeof(real));
  switch (width) {
    case 1: write_message<1>(*this, rows, stride, first, out.data()); break;
    case 2: write_message<2>(*this, rows, stride, first, out.data()); break;
    case 3: write_message<3>(*this, rows, stride, first, out.data()); break;
    case 4: write_message<4>(*this, rows, stride, first, out.data()); break;
    default: throw std::logic_error("split energy sums: 1 to 4 columns");
  }
}

BlockMerge::BlockMerge(std::size_t global_count, const std::vector<std::vector<int64_t>>& whole,
                       const std::vector<std::vector<int64_t>>& shared)
    : global_count_(global_count) {
  auto fail = [](const std::string& why) { throw std::logic_error("split energy sums: " + why); };
  if (whole.size() != shared.size()) fail("as many lists of whole blocks as of shared items expected");
  const std::size_t blocks = block_count(global_count);
  blocks_.assign(blocks, Source{-1, 0});
  for (std::size_t r = 0; r < whole.size(); ++r) {
    whole_count_.push_back(whole[r].size());
    shared_count_.push_back(shared[r].size());
    for (std::size_t k = 0; k < whole[r].size(); ++k) {
      const auto b = static_cast<std::size_t>(whole[r][k]);
      if (b >= blocks || blocks_[b].rank >= 0) fail("block " + std::to_string(b) + " is not one rank's");
      blocks_[b] = Source{static_cast<int>(r), k};
    }
  }
  // The shared blocks' items, block after block in global order.
  std::vector<std::size_t> filled(blocks, 0);
  for (const auto& list : shared)
    for (const int64_t g : list) {
      const auto b = static_cast<std::size_t>(g) / kOrderedBlock;
      if (g < 0 || b >= blocks || blocks_[b].rank >= 0) fail("item " + std::to_string(g) + " is in no shared block");
      ++filled[b];
    }
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    if (blocks_[b].rank >= 0) continue;
    if (filled[b] != block_length(global_count, b))
      fail("the ranks own " + std::to_string(filled[b]) + " of the " + std::to_string(block_length(global_count, b)) +
           " items of block " + std::to_string(b));
    blocks_[b].index = total;
    total += filled[b];
  }
  shared_rank_.assign(total, -1);
  for (std::size_t r = 0; r < shared.size(); ++r)
    for (std::size_t k = 0; k < shared[r].size(); ++k) {
      const auto g = static_cast<std::size_t>(shared[r][k]);
      if (k > 0 && shared[r][k] <= shared[r][k - 1]) fail("rank " + std::to_string(r) + "'s shared items are not ascending");
      int& owner = shared_rank_[blocks_[g / kOrderedBlock].index + g % kOrderedBlock];
      if (owner >= 0) fail("item " + std::to_string(g) + " has two owners");
      owner = static_cast<int>(r);
    }
}

// For a width known to the compiler, as write_message.
template <int W>
void BlockMerge::add_blocks(const std::vector<const Bytes*>& messages, std::vector<const char*>& next, double* total) const {
  constexpr std::size_t row = W * sizeof(real);
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const Source& src = blocks_[b];
    real s[W];
    if (src.rank >= 0) {
      std::memcpy(s, messages[src.rank]->data() + src.index * row, row);
    } else {
      // As blocked_sums: from 0, left to right in `real`, each column on its own.
      for (int c = 0; c < W; ++c) s[c] = 0;
      for (std::size_t i = src.index, end = i + block_length(global_count_, b); i < end; ++i) {
        real v[W];
        const char*& at = next[shared_rank_[i]];
        std::memcpy(v, at, row);
        at += row;
        for (int c = 0; c < W; ++c) s[c] += v[c];
      }
    }
    for (int c = 0; c < W; ++c) total[c] += static_cast<double>(s[c]);
  }
}

std::vector<double> BlockMerge::sums(const std::vector<const Bytes*>& messages, int width) const {
  const std::size_t row = width * sizeof(real);
  if (messages.size() != whole_count_.size()) throw std::logic_error("split energy sums: a message per rank expected");
  // Each rank's next shared item (its values follow its whole blocks' sums).
  std::vector<const char*> next(messages.size());
  for (std::size_t r = 0; r < messages.size(); ++r) {
    if (messages[r]->size() != (whole_count_[r] + shared_count_[r]) * row)
      throw std::logic_error("split energy sums: rank " + std::to_string(r) + "'s message does not fit its blocks");
    next[r] = messages[r]->data() + whole_count_[r] * row;
  }
  std::vector<double> total(static_cast<std::size_t>(width), 0.0);
  switch (width) {
    case 1: add_blocks<1>(messages, next, total.data()); break;
    case 2: add_blocks<2>(messages, next, total.data()); break;
    case 3: add_blocks<3>(messages, next, total.data()); break;
    case 4: add_blocks<4>(messages, next, total.data()); break;
    default: throw std::logic_error("split energy sums: 1 to 4 columns");
  }
  return total;
}

SplitSums::SplitSums(const ItemScope& scope) : transport_(*scope.transport) {
  for (int k = 0; k < 4; ++k) {
    share_[k] = BlockShare::of(scope.global[k], scope.owned[k], scope.global_count[k]);
    const auto whole = transport_.gather(to_bytes(share_[k].whole));
    const auto shared = transport_.gather(to_bytes(share_[k].shared));
    if (transport_.rank() != 0) continue;
    std::vector<std::vector<int64_t>> w, s;
    for (const auto& b : whole) w.push_back(from_bytes<int64_t>(b));
    for (const auto& b : shared) s.push_back(from_bytes<int64_t>(b));
    merge_[k] = BlockMerge(scope.global_count[k], w, s);
  }
}

std::vector<double> SplitSums::sums(ClContext& cl, const compute::buffer& values, std::size_t count, int stride,
                                    int first, int width, ItemKind kind) {
  const int k = static_cast<int>(kind);
  const std::size_t n = count * stride;
  if (rows_.size() < n) rows_.resize(n);
  if (n > 0) cl.queue().enqueue_read_buffer(values, 0, n * sizeof(real), rows_.data());
  share_[k].message(rows_.data(), stride, first, width, message_[k]);
  transport_.gather_into(message_[k], received_[k]);
  std::vector<double> sum;
  if (transport_.rank() == 0) {
    std::vector<const Bytes*> all{&message_[k]};
    for (std::size_t r = 1; r < received_[k].size(); ++r) all.push_back(&received_[k][r]);
    sum = merge_[k].sums(all, width);
  }
  return from_bytes<double>(transport_.broadcast(to_bytes(sum)));
}

std::vector<uint64_t> count_below(const std::vector<cl_ulong>& sorted_keys, const std::vector<cl_ulong>& queries) {
  // Consecutive queries of a run are close in the list (a few dozen couples apart), so
  // each search gallops forward from the last answer instead of halving the whole list.
  std::vector<uint64_t> out(queries.size());
  const std::size_t n = sorted_keys.size();
  std::size_t at = 0;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const cl_ulong key = queries[q];
    if (q > 0 && key < queries[q - 1]) at = 0;  // a new run
    // Every key before `lo` is below `key`; widen until keys[lo + step − 1] is not.
    std::size_t lo = at, step = 1;
    while (lo + step <= n && sorted_keys[lo + step - 1] < key) lo += step, step *= 2;
    const auto end = sorted_keys.begin() + static_cast<std::ptrdiff_t>(std::min(n, lo + step));
    at = static_cast<std::size_t>(std::lower_bound(sorted_keys.begin() + static_cast<std::ptrdiff_t>(lo), end, key) -
                                  sorted_keys.begin());
    out[q] = at;
  }
  return out;
}

double tree_group_sums(const std::vector<std::pair<uint64_t, real>>& nonzero, std::size_t group) {
  // Only the groups that hold a nonzero value are summed, by group_sum4's tree
  // (scratch[l] += scratch[l + s], s = group/2 … 1); the others sum to a zero, and a zero
  // leaves the double total (+0 at the start, never −0 after) as it is. The entries not
  // given are +0 here where the device may have had a −0 (a touching couple that stores
  // nothing): x + ±0 = x for x ≠ 0 and a sum of zeros is a zero, so every node of the
  // tree holds the same value in both or a zero in both, and a zero adds nothing.
  std::vector<real> scratch(group);
  double total = 0;
  for (std::size_t k = 0; k < nonzero.size();) {
    const uint64_t g = nonzero[k].first / group;
    std::fill(scratch.begin(), scratch.end(), real(0));
    for (; k < nonzero.size() && nonzero[k].first / group == g; ++k) scratch[nonzero[k].first % group] = nonzero[k].second;
    for (std::size_t s = group / 2; s > 0; s >>= 1)
      for (std::size_t l = 0; l < s; ++l) scratch[l] += scratch[l + s];
    total += static_cast<double>(scratch[0]);
  }
  return total;
}

MemoryPlan OrderedSums::plan(std::size_t max_items) {
  const std::size_t blocks = std::max<std::size_t>(1, (max_items + kOrderedBlock - 1) / kOrderedBlock);
  return MemoryPlan().add("ordered_sums partial", 4 * blocks * sizeof(real));
}

OrderedSums::OrderedSums(ClContext& cl, std::size_t max_items) : cl_(cl) {
  kernel_ = compute::kernel(cl.build(kernel_source::ordered_sum, {{"ORDERED_BLOCK", std::to_string(kOrderedBlock)}}),
                            "ordered_block_sums");
  partial_ = plan(max_items).allocate(cl, "ordered_sums partial");
}

namespace {
// The blocks' sums added in block order, in double.
std::vector<double> add_blocks(const std::vector<real>& partial, std::size_t blocks, int width) {
  std::vector<double> total(static_cast<std::size_t>(width), 0.0);
  for (std::size_t b = 0; b < blocks; ++b)
    for (int c = 0; c < width; ++c) total[c] += static_cast<double>(partial[b * width + c]);
  return total;
}
}  // namespace

std::size_t OrderedSums::launch(const compute::buffer& values, std::size_t count, int stride, int first, int width) {
  const std::size_t blocks = (count + kOrderedBlock - 1) / kOrderedBlock;
  bind_args(kernel_)("n", static_cast<cl_uint>(count))("stride", static_cast<cl_uint>(stride))(
      "first", static_cast<cl_uint>(first))("width", static_cast<cl_uint>(width))("values", values)("partial", partial_)
      .done();
  cl_.enqueue(kernel_, blocks);
  return blocks;
}

std::vector<double> OrderedSums::sums(const compute::buffer& values, std::size_t count, int stride, int first, int width) {
  if (count == 0) return std::vector<double>(static_cast<std::size_t>(width), 0.0);
  const std::size_t blocks = launch(values, count, stride, first, width);
  return add_blocks(download<real>(cl_, partial_, blocks * width), blocks, width);
}

PendingSums OrderedSums::queue(const compute::buffer& values, std::size_t count, int stride, int first, int width,
                               RowReads& reads) {
  if (count == 0) return sums_now(std::vector<double>(static_cast<std::size_t>(width), 0.0));
  const std::size_t blocks = launch(values, count, stride, first, width);
  // The next launch reuses partial_; the in-order queue copies it out before that runs.
  auto partial = reads.read<real>(partial_, blocks * width);
  return [partial, blocks, width] { return add_blocks(partial(), blocks, width); };
}

}  // namespace fdem
