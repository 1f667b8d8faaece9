#include "engine/parallel/halo.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <string>

#include "engine/device/kernel_args.hpp"

namespace fdem {

size_t HaloPlan::sent() const {
  size_t n = 0;
  for (const auto& s : send) n += s.size();
  return n;
}
size_t HaloPlan::received() const {
  size_t n = 0;
  for (const auto& r : receive) n += r.size();
  return n;
}

HaloPlan halo_plan(const Model& global, const Partition& partition, const LocalModel& local, int rank) {
  const auto owner = node_owners(global, partition);
  HaloPlan plan;
  plan.send.resize(partition.parts);
  plan.receive.resize(partition.parts);
  std::vector<int> local_of(global.num_nodes(), -1);
  for (size_t i = 0; i < local.node_global.size(); ++i) local_of[local.node_global[i]] = static_cast<int>(i);
  for (int q = 0; q < partition.parts; ++q) {
    if (q == rank) continue;
    const auto held = held_nodes(global, partition, owner, q);
    for (size_t v = 0; v < global.num_nodes(); ++v) {
      if (owner[v] == rank && held[v]) plan.send[q].push_back(local_of[v]);
      if (owner[v] == q && local_of[v] >= 0) plan.receive[q].push_back(local_of[v]);
    }
  }
  return plan;
}

namespace {
std::vector<cl_uint> concatenated(const std::vector<std::vector<int>>& lists) {
  std::vector<cl_uint> out;
  for (const auto& l : lists) out.insert(out.end(), l.begin(), l.end());
  if (out.empty()) out.push_back(0);
  return out;
}
}  // namespace

MemoryPlan HaloExchange::memory(const HaloPlan& plan, bool contact) {
  const size_t sent = std::max<size_t>(1, plan.sent()), received = std::max<size_t>(1, plan.received());
  MemoryPlan p;
  p.add("halo send_index", sent * sizeof(cl_uint))
      .add("halo receive_index", received * sizeof(cl_uint))
      .add("halo send_values", sent * sizeof(real4))
      .add("halo receive_values", received * sizeof(real4));
  // Contact forces travel the other way: out of the ghosts, into the owned nodes.
  if (contact) p.add("halo contact_out", received * sizeof(cl_long2)).add("halo contact_in", sent * sizeof(cl_long2));
  return p;
}

HaloExchange::HaloExchange(ClContext& cl, DeviceArrays& arrays, HaloPlan plan, Transport& transport, bool contact)
    : cl_(cl), arrays_(arrays), plan_(std::move(plan)), transport_(transport), sent_(plan_.sent()),
      received_(plan_.received()), contact_(contact) {
  std::map<std::string, std::string> defines;
  if (contact_) defines["HALO_CONTACT"] = "1";
  const auto program = cl.build(kernel_source::halo, defines);
  pack_ = compute::kernel(program, "halo_pack");
  unpack_ = compute::kernel(program, "halo_unpack");
  const auto send_index = concatenated(plan_.send), receive_index = concatenated(plan_.receive);
  const MemoryPlan own = memory(plan_, contact_);
  send_index_ = own.allocate(cl, "halo send_index");
  receive_index_ = own.allocate(cl, "halo receive_index");
  upload(cl, send_index_, send_index);
  upload(cl, receive_index_, receive_index);
  send_values_ = own.allocate(cl, "halo send_values");
  receive_values_ = own.allocate(cl, "halo receive_values");
  send_host_.resize(sent_);
  receive_host_.resize(received_);
  bind_args(pack_)("n", static_cast<cl_uint>(sent_))("index", send_index_)("position", arrays.position)(
      "velocity", arrays.velocity)("packed", send_values_).done();
  bind_args(unpack_)("n", static_cast<cl_uint>(received_))("index", receive_index_)("packed", receive_values_)(
      "position", arrays.position)("velocity", arrays.velocity).done();
  if (contact_) {
    contact_pack_ = compute::kernel(program, "halo_contact_pack");
    contact_add_ = compute::kernel(program, "halo_contact_add");
    contact_out_ = own.allocate(cl, "halo contact_out");
    contact_in_ = own.allocate(cl, "halo contact_in");
    contact_out_host_.resize(received_);
    contact_in_host_.resize(sent_);
    bind_args(contact_pack_)("n", static_cast<cl_uint>(received_))("index", receive_index_)(
        "contact_acc", arrays.contact_acc)("packed", contact_out_).done();
    bind_args(contact_add_)("n", static_cast<cl_uint>(sent_))("index", send_index_)("packed", contact_in_)(
        "contact_acc", arrays.contact_acc).done();
  }
}

void HaloExchange::begin_contact() {
  if (!contact_ || !received_) return;
  cl_.enqueue(contact_pack_, received_);
  contact_read_ = cl_.queue().enqueue_read_buffer_async(contact_out_, 0, received_ * sizeof(cl_long2),
                                                         contact_out_host_.data());
}

void HaloExchange::finish_contact() {
  if (!contact_) return;
  const auto start = std::chrono::steady_clock::now();
  if (received_) contact_read_.wait();
  size_t at = 0;
  for (size_t q = 0; q < plan_.receive.size(); ++q) {
    const size_t n = plan_.receive[q].size();
    if (n)
      transport_.post(static_cast<int>(q), to_bytes(std::vector<cl_long2>(contact_out_host_.begin() + at,
                                                                           contact_out_host_.begin() + at + n)));
    at += n;
  }
  at = 0;
  for (size_t q = 0; q < plan_.send.size(); ++q) {
    const size_t n = plan_.send[q].size();
    if (!n) continue;
    const auto values = from_bytes<cl_long2>(transport_.receive(static_cast<int>(q)));
    if (values.size() != n)
      throw DeviceError("contact halo exchange: rank " + std::to_string(transport_.rank()) + " expected " +
                        std::to_string(n) + " nodes' contact forces from rank " + std::to_string(q) + " and got " +
                        std::to_string(values.size()));
    std::copy(values.begin(), values.end(), contact_in_host_.begin() + at);
    at += n;
  }
  transport_.complete();
  if (sent_) {
    cl_.queue().enqueue_write_buffer(contact_in_, 0, sent_ * sizeof(cl_long2), contact_in_host_.data());
    cl_.enqueue(contact_add_, sent_);
  }
  if (cl_.profiling()) {
    cl_.finish();
    cl_.add_host_time("contact halo exchange (host wall: wait for the read, messages, write, add)",
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
}

void HaloExchange::exchange() {
  if (!cl_.profiling()) {
    send();
    receive();
    return;
  }
  cl_.finish();  // the step's kernels, so that the time below is the exchange's own
  const auto start = std::chrono::steady_clock::now();
  send();
  receive();
  cl_.finish();
  cl_.add_host_time("halo exchange (host wall: pack, read, messages, write, unpack)",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

void HaloExchange::send() {
  if (sent_) {
    cl_.enqueue(pack_, sent_);
    cl_.queue().enqueue_read_buffer(send_values_, 0, sent_ * sizeof(real4), send_host_.data());
  }
  size_t at = 0;
  for (size_t q = 0; q < plan_.send.size(); ++q) {
    const size_t n = plan_.send[q].size();
    if (n) transport_.post(static_cast<int>(q), to_bytes(std::vector<real4>(send_host_.begin() + at, send_host_.begin() + at + n)));
    at += n;
  }
}

void HaloExchange::receive() {
  size_t at = 0;
  for (size_t q = 0; q < plan_.receive.size(); ++q) {
    const size_t n = plan_.receive[q].size();
    if (!n) continue;
    const auto values = from_bytes<real4>(transport_.receive(static_cast<int>(q)));
    if (values.size() != n)
      throw DeviceError("halo exchange: rank " + std::to_string(transport_.rank()) + " expected " + std::to_string(n) +
                        " ghost nodes from rank " + std::to_string(q) + " and got " + std::to_string(values.size()));
    std::copy(values.begin(), values.end(), receive_host_.begin() + at);
    at += n;
  }
  transport_.complete();
  if (received_) {
    // Blocking write: the host array is reused by the next step's receive.
    cl_.queue().enqueue_write_buffer(receive_values_, 0, received_ * sizeof(real4), receive_host_.data());
    cl_.enqueue(unpack_, received_);
  }
}

}  // namespace fdem
