// What a stage allocates on the device, said by the stage itself. Each stage (and
// DeviceArrays) has a static `plan(...)` that lists its device arrays by name and size;
// its constructor allocates each array through `MemoryPlan::allocate(cl, name)`, so the
// list is the one place a size is written. Solver::plan adds up the plans of the stages
// that a model builds: the figure of `fdem check`, `fdem bench` and of the
// too-little-memory error.
#pragma once
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "engine/device/cl_context.hpp"

namespace fdem {

// Work-groups of `group_size` that cover n work-items (as ClContext::enqueue launches them).
inline std::size_t groups_for(std::size_t n, std::size_t group_size) { return (n + group_size - 1) / group_size; }

class MemoryPlan {
 public:
  enum class Lifetime {
    Resident,  // allocated by the constructor and kept (a growable array: its first capacity)
    SetUp,     // allocated while the Solver is built, released before its constructor ends
    Scratch,   // allocated during a step by a library outside ClContext (Boost.Compute's sorts)
    Output,    // allocated through ClContext for an output step (frame, history row, probes),
               // between steps, and released before the next step (Solver::release_output)
    Detection,  // allocated by each contact detection while it finds its couples (with the
                // hashes' sort scratch), released before the couples' sort
    EnergyRow,  // allocated by an energy-row step for its per-item energies, summed into
                // block partials and released within that step (after the detection)
  };
  struct Array {
    std::string name;
    std::size_t bytes;  // as asked; ClContext::allocation_size(bytes) is what the device holds
    Lifetime lifetime;
  };

  MemoryPlan& add(const std::string& name, std::size_t bytes, Lifetime lifetime = Lifetime::Resident) {
    for (const auto& a : arrays_)
      if (a.name == name) throw DeviceError("memory plan: array '" + name + "' listed twice");
    arrays_.push_back({name, bytes, lifetime});
    return *this;
  }
  MemoryPlan& add(const MemoryPlan& other) {
    for (const auto& a : other.arrays_) add(a.name, a.bytes, a.lifetime);
    return *this;
  }

  // The array `name` as listed (DeviceError when the plan does not list it).
  const Array& array(const std::string& name) const {
    for (const auto& a : arrays_)
      if (a.name == name) return a;
    throw DeviceError("memory plan: no array '" + name + "'");
  }
  std::size_t bytes(const std::string& name) const { return array(name).bytes; }
  // Allocates the listed array `name` at its listed size.
  compute::buffer allocate(ClContext& cl, const std::string& name) const { return cl.allocate(bytes(name), name); }

  // Device bytes the resident arrays hold (each as ClContext::allocate rounds it).
  std::size_t resident() const { return sum(Lifetime::Resident); }
  // Bytes allocated through ClContext while the Solver is built (resident + set-up arrays):
  // ClContext::device_bytes_peak rises by at most this much during the construction (by
  // less when set-up arrays are counted out before the last resident ones are made).
  std::size_t construction_peak() const { return resident() + sum(Lifetime::SetUp); }
  // The most the transient arrays hold at once: the largest set-up or scratch array (no
  // two of them exist at once: set-up arrays during the construction, scratch within a
  // step), or all output arrays together (they exist together, between two steps), or
  // all detection arrays together (within a detection, before its couples' sort), or an
  // energy-row step's per-item energies together (after the detection, within the step).
  std::size_t largest_transient() const {
    std::size_t most = std::max({sum(Lifetime::Output), sum(Lifetime::Detection), sum(Lifetime::EnergyRow)});
    for (const auto& a : arrays_)
      if (a.lifetime == Lifetime::SetUp || a.lifetime == Lifetime::Scratch)
        most = std::max(most, ClContext::allocation_size(a.bytes));
    return most;
  }
  // The figure the too-little-memory check compares with the device's memory.
  std::size_t total() const { return resident() + largest_transient(); }

  const std::vector<Array>& arrays() const { return arrays_; }

 private:
  std::size_t sum(Lifetime lifetime) const {
    std::size_t s = 0;
    for (const auto& a : arrays_)
      if (a.lifetime == lifetime) s += ClContext::allocation_size(a.bytes);
    return s;
  }
  std::vector<Array> arrays_;
};

}  // namespace fdem
