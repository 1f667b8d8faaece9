// The OpenCL context object: owns platform, device, context and queue, and compiles
// stage programs. Programs are assembled in a fixed order: global defines, precision
// typedefs, the layouts (engine/model/layouts.hpp), cl_kernels/common.cl, the stage's own
// defines, the stage's source.
#pragma once
#include <atomic>
#include <memory>
#include <boost/compute/core.hpp>
#include <boost/compute/event.hpp>
#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "embedded_kernels.hpp"

namespace fdem {

namespace compute = boost::compute;


struct DeviceInfo {
  int platform_index = 0;
  int device_index = 0;
  std::string platform_name;
  std::string device_name;
  std::string version;
  bool is_gpu = false;
  bool has_fp64 = false;
  bool nv_compiler_options = false;  // cl_nv_compiler_options: -cl-nv-maxrregcount and others
  std::size_t global_memory = 0;
  std::size_t max_allocation = 0;
  unsigned compute_units = 0;
};

// Every device of every platform, in ICD order.
std::vector<DeviceInfo> list_devices();

class ClContext {
 public:
  // `choice`: "auto" (first GPU with fp64, else the first CPU device), "gpu", "cpu",
  // or "P:D" (platform P, device D as `fdem devices` numbers them). Empty → the
  // FDEM_DEVICE environment variable, else "auto". Throws DeviceError when nothing fits.
  explicit ClContext(const std::string& choice = "", bool profiling = false);

  const compute::device& device() const { return device_; }
  const compute::context& context() const { return context_; }
  compute::command_queue& queue() { return queue_; }
  const DeviceInfo& info() const { return info_; }
  std::string description() const;

  // Compiles a stage's program (kernel_source::integrate, …: one symbol per file of
  // cl_kernels/) with the layouts of engine/model/layouts.hpp and extra defines (name → value).
  // `libraries`: files of shared functions (e.g. kernel_source::couple_geometry) placed
  // ahead of the stage's own text, after the defines. Throws BuildError carrying the
  // stage name and the build log.
  // `register_cap` > 0: on NVIDIA GPUs (cl_nv_compiler_options) no work-item of the
  // program uses more registers than that (-cl-nv-maxrregcount); elsewhere it does nothing.
  // The cap changes register allocation only, not one operation: the same bits.
  compute::program build(const KernelSource& stage, const std::map<std::string, std::string>& defines = {},
                         const std::vector<const KernelSource*>& libraries = {}, int register_cap = 0) const;

  // Work-group size used for 1D launches; global sizes are rounded up to it.
  std::size_t group_size() const { return group_size_; }
  // A work-group size from the environment variable `name` (tuning): 0 when unset or
  // empty, else a power of two from `smallest` to the device's limit, or a DeviceError.
  std::size_t group_size_from_env(const char* name, std::size_t smallest = 1) const;

  // Enqueues a 1D kernel over `n` work-items (rounded up; kernels guard their index), in
  // work-groups of `local` items (0: group_size(); only for kernels without __local
  // arrays sized by GROUP_SIZE). Never waits. Throws DeviceError naming the kernel on failure.
  void enqueue(const compute::kernel& kernel, std::size_t n, std::size_t local = 0);

  // Allocates a device buffer; `what` names it in the error when allocation fails.
  // Stages allocate through their MemoryPlan (engine/device/memory_plan.hpp), which calls this.
  compute::buffer allocate(std::size_t bytes, const std::string& what) const;
  // The bytes allocate(bytes) takes: an empty array gets one real (OpenCL has no empty buffers).
  static std::size_t allocation_size(std::size_t bytes);
  // Bytes of the buffers allocate() made that are still alive (OpenCL destructor
  // callbacks count them down), and the most there ever were (since the last
  // restart_device_bytes_peak(), which sets the peak to what is in use now).
  std::size_t device_bytes_in_use() const { return live_->bytes.load(); }
  std::size_t device_bytes_peak() const { return live_->peak.load(); }
  void restart_device_bytes_peak() { live_->peak.store(live_->bytes.load()); }

  void finish();  // waits for the queue; DeviceError on failure

  // Kernel profiling (only with `profiling` at construction): every enqueue() keeps its
  // event; collect_profile() adds the finished ones' device times per kernel name.
  bool profiling() const { return profiling_; }
  void collect_profile();
  struct KernelTime {
    double seconds = 0;
    long launches = 0;
  };
  const std::map<std::string, KernelTime>& profile() const { return profile_; }
  // Host-timed sections (e.g. a whole detection with its sorts), added by callers; also
  // from the outputs' record thread (OutputSet), so the table is locked.
  void add_host_time(const std::string& name, double seconds);

 private:
  compute::device device_;
  compute::context context_;
  compute::command_queue queue_;
  DeviceInfo info_;
  std::size_t group_size_ = 64;
  bool profiling_ = false;
  std::vector<std::pair<std::string, compute::event>> pending_;
  struct LiveBytes {
    std::atomic<std::size_t> bytes{0}, peak{0};
  };
  std::shared_ptr<LiveBytes> live_ = std::make_shared<LiveBytes>();
  std::map<std::string, KernelTime> profile_;
  std::shared_ptr<std::mutex> profile_lock_ = std::make_shared<std::mutex>();
};

}  // namespace fdem
