// The ghost exchange of a split run (ARCHITECTURE.md, "Scale-out"): after every step,
// each rank sends the positions and velocities of the nodes it owns that other ranks hold
// as ghosts, and takes its own ghosts' from their owners. The lists are in the global
// node order on both sides, so nothing but the values travels. The same class runs the
// MPI run (engine/scale_out.*) and the tests' in-process emulation (tests/test_partition.cpp).
#pragma once
#include <vector>

#include "engine/cl_context.hpp"
#include "engine/device_arrays.hpp"
#include "engine/memory_plan.hpp"
#include "engine/partition.hpp"
#include "engine/transport.hpp"

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
  HaloExchange(ClContext& cl, DeviceArrays& arrays, HaloPlan plan, Transport& transport);
  // The device arrays of the exchange of `plan` (index lists and packed values).
  static MemoryPlan memory(const HaloPlan& plan);
  // Packs the sent nodes on the device, reads them (waits for the queue) and posts them.
  void send();
  // Receives every peer's values and writes them into the ghost nodes (enqueued; the
  // next step's kernels follow them in the queue).
  void receive();
  // send() then receive(). With profiling, the step is finished first and the exchange
  // timed alone ("halo exchange" in the profile).
  void exchange();
  const HaloPlan& plan() const { return plan_; }

 private:
  ClContext& cl_;
  DeviceArrays& arrays_;
  HaloPlan plan_;
  Transport& transport_;
  size_t sent_ = 0, received_ = 0;
  compute::kernel pack_, unpack_;
  compute::buffer send_index_, receive_index_, send_values_, receive_values_;
  std::vector<real4> send_host_, receive_host_;
};

}  // namespace fdem
