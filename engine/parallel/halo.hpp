// The ghost exchange of a split run (ARCHITECTURE.md, "Scale-out"): after every step,
// each rank sends the positions and velocities of the nodes it owns that other ranks hold
// as ghosts, and takes its own ghosts' from their owners. The lists are in the global
// node order on both sides, so nothing but the values travels. The same class runs the
// MPI run (engine/run/split_run.*) and the tests' in-process emulation (tests/test_partition.cpp).
#pragma once
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/device/memory_plan.hpp"
#include "engine/parallel/partition.hpp"
#include "engine/parallel/transport.hpp"

namespace fdem {

// Per peer rank, the local indices of the nodes sent to it (owned here, held there) and
// of those received from it (held here, owned there), each in global node order.
struct HaloPlan {
  std::vector<std::vector<int>> send, receive;  // [peer] → local node indices
  size_t sent() const;
  size_t received() const;
};

// The plan of `rank` from the global model and its partition (every rank computes the
// held nodes of every other from the same data, so no set-up message is needed).
HaloPlan halo_plan(const Model& global, const Partition& partition, const LocalModel& local, int rank);

class HaloExchange {
 public:
  // contact: the model has contact (exchange_contact).
  HaloExchange(ClContext& cl, DeviceArrays& arrays, HaloPlan plan, Transport& transport, bool contact = false);
  // The device arrays of the exchange of `plan` (index lists and packed values).
  static MemoryPlan memory(const HaloPlan& plan, bool contact = false);
  // Packs the sent nodes on the device, reads them (waits for the queue) and posts them.
  void send();
  // Receives every peer's values and writes them into the ghost nodes (enqueued; the
  // next step's kernels follow them in the queue).
  void receive();
  // send() then receive(). With profiling, the step is finished first and the exchange
  // timed alone ("halo exchange" in the profile).
  void exchange();
  // Contact (a split run whose model has contact): the fixed-point contact forces the
  // couples of this rank put on its ghost nodes go to their owners, which add them
  // (integers: the sum is exact and does not depend on the order, so an owned node ends
  // with one rank's total). The same lists as exchange(), travelled the other way. Waits
  // for the queue (the contact stage), then enqueues the additions. In two halves so that
  // the messages overlap the device's next kernels: begin_contact() enqueues the pack and
  // an asynchronous read (never waits), finish_contact() waits for that read, posts and
  // receives the messages and enqueues the additions.
  void exchange_contact() {
    begin_contact();
    finish_contact();
  }
  void begin_contact();
  void finish_contact();
  const HaloPlan& plan() const { return plan_; }

 private:
  ClContext& cl_;
  DeviceArrays& arrays_;
  HaloPlan plan_;
  Transport& transport_;
  size_t sent_ = 0, received_ = 0;
  compute::kernel pack_, unpack_, contact_pack_, contact_add_;
  compute::buffer send_index_, receive_index_, send_values_, receive_values_, contact_out_, contact_in_;
  std::vector<real4> send_host_, receive_host_;
  std::vector<cl_long2> contact_out_host_, contact_in_host_;
  compute::event contact_read_;
  bool contact_ = false;
};

}  // namespace fdem
