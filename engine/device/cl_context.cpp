#include "engine/device/cl_context.hpp"

#include <boost/compute/exception.hpp>
#include <chrono>
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "base/errors.hpp"
#include "engine/model/layouts.hpp"
#include "engine/model/real.hpp"

namespace fdem {

namespace {

DeviceInfo describe(const compute::platform& platform, const compute::device& device,
                    int p, int d) {
  DeviceInfo info;
  info.platform_index = p;
  info.device_index = d;
  info.platform_name = platform.name();
  info.device_name = device.name();
  info.version = device.version();
  info.is_gpu = (device.type() & CL_DEVICE_TYPE_GPU) != 0;
  info.has_fp64 = device.supports_extension("cl_khr_fp64");
  info.nv_compiler_options = device.supports_extension("cl_nv_compiler_options");
  info.global_memory = device.global_memory_size();
  info.max_allocation = device.get_info<cl_ulong>(CL_DEVICE_MAX_MEM_ALLOC_SIZE);
  info.compute_units = device.compute_units();
  return info;
}

std::string device_list_text() {
  std::ostringstream out;
  for (const auto& d : list_devices())
    out << "\n  " << d.platform_index << ":" << d.device_index << "  " << d.device_name << " ("
        << d.platform_name << (d.has_fp64 ? ", fp64" : ", no fp64") << ")";
  return out.str();
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  std::vector<compute::platform> platforms;
  try {
    platforms = compute::system::platforms();
  } catch (const compute::opencl_error&) {
    return out;  // no ICD installed: an empty list, the caller explains
  }
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<compute::device> devices;
    try {
      devices = platforms[p].devices();
    } catch (const compute::opencl_error&) {
      continue;
    }
    for (size_t d = 0; d < devices.size(); ++d)
      out.push_back(describe(platforms[p], devices[d], static_cast<int>(p), static_cast<int>(d)));
  }
  return out;
}

ClContext::ClContext(const std::string& requested, bool profiling) {
  std::string choice = requested;
  if (choice.empty()) {
    const char* env = std::getenv("FDEM_DEVICE");
    choice = (env && *env) ? env : "auto";
  }
  const auto devices = list_devices();
  if (devices.empty())
    throw DeviceError(
        "no OpenCL platform found. Install a driver: on Debian `apt-get install "
        "pocl-opencl-icd` gives a CPU device.");

  const DeviceInfo* picked = nullptr;
  auto usable = [](const DeviceInfo& d) { return d.has_fp64 || !kDoublePrecision; };
  if (choice == "auto") {
    for (const auto& d : devices)
      if (d.is_gpu && usable(d)) { picked = &d; break; }
    if (!picked)
      for (const auto& d : devices)
        if (!d.is_gpu && usable(d)) { picked = &d; break; }
  } else if (choice == "gpu" || choice == "cpu") {
    for (const auto& d : devices)
      if (d.is_gpu == (choice == "gpu") && usable(d)) { picked = &d; break; }
  } else {
    int p = -1, d = -1;
    char colon = 0;
    std::istringstream in(choice);
    if (!(in >> p >> colon >> d) || colon != ':' || !in.eof())
      throw InputError("--device '" + choice + "': expected auto, gpu, cpu or P:D (e.g. 0:1)");
    for (const auto& info : devices)
      if (info.platform_index == p && info.device_index == d) picked = &info;
    if (!picked) throw DeviceError("no OpenCL device " + choice + "; devices are:" + device_list_text());
    if (!usable(*picked))
      throw DeviceError("device " + choice + " (" + picked->device_name +
                        ") has no fp64 support; this build uses double precision");
  }
  if (!picked)
    throw DeviceError("no " + std::string(choice == "auto" ? "" : choice + " ") +
                      "OpenCL device with fp64 support; devices are:" + device_list_text());

  info_ = *picked;
  try {
    device_ = compute::system::platforms()[info_.platform_index].devices()[info_.device_index];
    context_ = compute::context(device_);
    queue_ = compute::command_queue(context_, device_,
                                    profiling ? compute::command_queue::enable_profiling : 0);
  } catch (const compute::opencl_error& e) {
    throw DeviceError("cannot open OpenCL device " + info_.device_name + ": " + e.what());
  }
  group_size_ = info_.is_gpu ? 256 : 64;
  // FDEM_GROUP_SIZE (a power of two up to the device's limit) overrides it, for tuning.
  if (const std::size_t size = group_size_from_env("FDEM_GROUP_SIZE")) group_size_ = size;
  profiling_ = profiling;
}

std::size_t ClContext::group_size_from_env(const char* name, std::size_t smallest) const {
  const char* env = std::getenv(name);
  if (!env || !*env) return 0;
  char* end = nullptr;
  const unsigned long size = std::strtoul(env, &end, 10);
  if (*end != '\0' || size < std::max<std::size_t>(smallest, 1) || (size & (size - 1)) != 0 ||
      size > device_.max_work_group_size())
    throw DeviceError(std::string(name) + "=" + env + " is not a power of two " +
                      (smallest > 1 ? "from " + std::to_string(smallest) + " " : std::string()) + "up to " +
                      std::to_string(device_.max_work_group_size()));
  return size;
}

std::string ClContext::description() const {
  std::ostringstream out;
  out << info_.device_name << " (" << info_.platform_name << ", device " << info_.platform_index
      << ":" << info_.device_index << ", " << (kDoublePrecision ? "double" : "float") << ")";
  return out.str();
}

namespace {
// Tuning experiments (docs/performance-notes.md): FDEM_CL_OPTIONS adds compiler options to
// every stage's build ("-cl-nv-verbose"), or to one stage's with "STAGE=OPTIONS", several
// separated by ";" ("cohesive_forces=-cl-nv-maxrregcount=64").
std::string extra_build_options(const std::string& stage) {
  const char* env = std::getenv("FDEM_CL_OPTIONS");
  if (!env || !*env) return "";
  std::string out, all = env;
  size_t start = 0;
  while (start <= all.size()) {
    const size_t end = std::min(all.find(';', start), all.size());
    const std::string item = all.substr(start, end - start);
    const size_t eq = item.find('=');
    const bool scoped = eq != std::string::npos && item.compare(0, 1, "-") != 0;
    if (!scoped) out += " " + item;
    else if (item.substr(0, eq) == stage) out += " " + item.substr(eq + 1);
    start = end + 1;
  }
  return out;
}
}  // namespace

compute::program ClContext::build(const KernelSource& stage, const std::map<std::string, std::string>& defines,
                                  const std::vector<const KernelSource*>& libraries, int register_cap) const {
  std::ostringstream text;
  text << "// stage: " << stage.stage << "\n";
  if (kDoublePrecision) text << "#define FDEM_DOUBLE 1\n";
  // CPU devices run a work-group's items one after the other (docs/performance-notes.md,
  // "Session 30"): FDEM_CPU_DEVICE takes some group reductions as one loop there
  // (cl_kernels/common.cl), FDEM_CPU_PREFETCH has the kernels ask for the scattered node
  // records of the items a few places on. Neither moves a bit; FDEM_CPU_SERIAL=0 and
  // FDEM_CPU_PREFETCH=0 leave them out, for comparisons.
  if (!info_.is_gpu) {
    auto switched_off = [](const char* name) {
      const char* value = std::getenv(name);
      return value && std::string(value) == "0";
    };
    if (!switched_off("FDEM_CPU_SERIAL")) text << "#define FDEM_CPU_DEVICE 1\n";
    if (!switched_off("FDEM_CPU_PREFETCH")) text << "#define FDEM_CPU_PREFETCH 1\n";
  }
  for (const auto& [name, value] : layout::defines()) text << "#define " << name << " " << value << "\n";
  text << kernel_source::common.text << "\n";
  for (const auto& [name, value] : defines) text << "#define " << name << " " << value << "\n";
  for (const KernelSource* library : libraries) text << "// library: " << library->stage << "\n#line 1\n" << library->text << "\n";
  text << "#line 1\n" << stage.text;

  compute::program program;
  try {
    program = compute::program::create_with_source(text.str(), context_);
  } catch (const compute::opencl_error& e) {
    throw BuildError(stage.stage, e.what());
  }
  try {
    // Argument names are kept so that KernelArgs can check each binding by name.
    std::string options = "-cl-std=CL1.2 -cl-kernel-arg-info";
    if (register_cap > 0 && info_.nv_compiler_options) options += " -cl-nv-maxrregcount=" + std::to_string(register_cap);
    program.build(options + extra_build_options(stage.stage));
    if (const char* env = std::getenv("FDEM_CL_BUILD_LOG"); env && *env == '1')
      std::cerr << "build log of stage " << stage.stage << ":\n" << program.build_log() << "\n";
  } catch (const compute::opencl_error& e) {
    std::string log;
    try {
      log = program.build_log();
    } catch (...) {
    }
    throw BuildError(stage.stage, std::string(e.what()) + "\n" + log);
  }
  return program;
}

void ClContext::enqueue(const compute::kernel& kernel, std::size_t n, std::size_t group) {
  if (n == 0) return;
  const std::size_t local = group ? group : group_size_;
  const std::size_t global = (n + local - 1) / local * local;
  try {
    if (profiling_) {
      compute::event done = queue_.enqueue_1d_range_kernel(kernel, 0, global, local);
      pending_.emplace_back(kernel.name(), done);
      return;
    }
    // Without profiling no event is asked for: the driver then creates and releases none,
    // which a small model, bound by launches (a few µs each), notices.
    const cl_int status = clEnqueueNDRangeKernel(queue_.get(), kernel.get(), 1, nullptr, &global, &local, 0, nullptr, nullptr);
    if (status != CL_SUCCESS) throw compute::opencl_error(status);
  } catch (const compute::opencl_error& e) {
    throw DeviceError("enqueue of kernel '" + kernel.name() + "' over " + std::to_string(n) +
                      " items failed: " + e.what());
  }
}

std::size_t ClContext::allocation_size(std::size_t bytes) { return bytes == 0 ? sizeof(real) : bytes; }

compute::buffer ClContext::allocate(std::size_t bytes, const std::string& what) const {
  if (bytes > info_.max_allocation)
    throw DeviceError("device array '" + what + "' needs " + std::to_string(bytes) +
                      " bytes, more than the device's largest allocation (" +
                      std::to_string(info_.max_allocation) + " bytes)");
  try {
    const std::size_t size = allocation_size(bytes);
    compute::buffer buffer(context_, size, compute::memory_object::read_write);
    // The callback owns a reference to the counter, so it may run after this context is gone.
    auto* owner = new std::pair<std::shared_ptr<LiveBytes>, std::size_t>(live_, size);
    const cl_int status = clSetMemObjectDestructorCallback(
        buffer.get(),
        [](cl_mem, void* data) {
          auto* o = static_cast<std::pair<std::shared_ptr<LiveBytes>, std::size_t>*>(data);
          o->first->bytes -= o->second;
          delete o;
        },
        owner);
    if (status != CL_SUCCESS) {
      delete owner;
    } else {
      const std::size_t now = live_->bytes += size;
      std::size_t peak = live_->peak.load();
      while (now > peak && !live_->peak.compare_exchange_weak(peak, now)) {
      }
    }
    return buffer;
  } catch (const compute::opencl_error& e) {
    throw DeviceError("cannot allocate device array '" + what + "' (" + std::to_string(bytes) +
                      " bytes): " + e.what());
  }
}

void ClContext::collect_profile() {
  if (!profiling_) return;
  finish();
  const std::lock_guard<std::mutex> lock(*profile_lock_);
  for (auto& [name, event] : pending_) {
    auto& entry = profile_[name];
    entry.seconds += 1e-9 * static_cast<double>(event.duration<std::chrono::nanoseconds>().count());
    entry.launches++;
  }
  pending_.clear();
}

void ClContext::add_host_time(const std::string& name, double seconds) {
  const std::lock_guard<std::mutex> lock(*profile_lock_);
  auto& entry = profile_[name];
  entry.seconds += seconds;
  entry.launches++;
}

void ClContext::finish() {
  try {
    queue_.finish();
  } catch (const compute::opencl_error& e) {
    throw DeviceError(std::string("device queue failed: ") + e.what());
  }
}

}  // namespace fdem
