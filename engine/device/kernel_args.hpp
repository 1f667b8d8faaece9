// Binding a kernel's arguments in the order its .cl file declares them, each with the
// name it has there. KernelArgs checks every name against the compiled kernel (programs
// keep their argument names: ClContext::build) and, at done(), that no argument was left
// unbound, so an argument added to a kernel and not to its stage, or bound in the wrong
// place, is a DeviceError naming the kernel and the argument at construction, never a
// silent wrong value. Arguments that change between launches are bound as a KernelArg
// and set before each enqueue.
#pragma once
#include <string>

#include <boost/compute/kernel.hpp>

#include "base/errors.hpp"

namespace fdem {

namespace compute = boost::compute;

// One argument of a kernel, set again before launches (a time, a count, a list that
// changes). Holds a reference to the kernel (OpenCL retains it).
template <class T>
class KernelArg {
 public:
  KernelArg() = default;
  KernelArg(const compute::kernel& kernel, cl_uint index) : kernel_(kernel), index_(index) {}
  void set(const T& value) { kernel_.set_arg(index_, value); }
  cl_uint index() const { return index_; }

 private:
  compute::kernel kernel_;
  cl_uint index_ = 0;
};

class KernelArgs {
 public:
  explicit KernelArgs(compute::kernel& kernel) : kernel_(kernel), arity_(static_cast<cl_uint>(kernel.arity())) {}

  // Binds the next argument, which the kernel must declare as `name`.
  template <class T>
  KernelArgs& operator()(const char* name, const T& value) {
    kernel_.set_arg(next(name), value);
    return *this;
  }
  // Binds the next argument to `initial` and returns it, to be set again before launches.
  template <class T>
  KernelArg<T> later(const char* name, const T& initial) {
    const cl_uint index = next(name);
    kernel_.set_arg(index, initial);
    return KernelArg<T>(kernel_, index);
  }
  // Every argument the kernel declares has been bound.
  void done() const {
    if (bound_ != arity_)
      throw DeviceError("kernel '" + kernel_.name() + "' declares " + std::to_string(arity_) +
                                           " arguments; its stage binds " + std::to_string(bound_) + " (next: '" +
                                           declared(bound_) + "')");
  }

 private:
  cl_uint next(const char* name) {
    if (bound_ >= arity_)
      throw DeviceError("kernel '" + kernel_.name() + "' declares " + std::to_string(arity_) +
                                           " arguments; its stage binds more (the next is '" + name + "')");
    const std::string there = declared(bound_);
    if (!there.empty() && there != name)
      throw DeviceError("kernel '" + kernel_.name() + "' argument " + std::to_string(bound_) + " is '" +
                                           there + "'; its stage binds '" + name + "' there");
    return bound_++;
  }
  // The argument's name in the .cl file, or "" where the platform does not keep names.
  std::string declared(cl_uint index) const {
    if (index >= arity_) return "";
    std::string name;
    try {
      name = kernel_.get_arg_info<std::string>(index, CL_KERNEL_ARG_NAME);
    } catch (const compute::opencl_error&) {
      return "";
    }
    // PoCL reports a parameter named like a built-in function (step, …) as "_cl_step".
    if (name.compare(0, 4, "_cl_") == 0) name.erase(0, 4);
    return name;
  }

  compute::kernel& kernel_;
  cl_uint arity_;
  cl_uint bound_ = 0;
};

// For binding a kernel's arguments in one statement: bind_args(k)("n", n)(…).done();
inline KernelArgs bind_args(compute::kernel& kernel) { return KernelArgs(kernel); }

}  // namespace fdem
