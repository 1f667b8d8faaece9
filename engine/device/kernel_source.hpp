// One embedded OpenCL source file: its stage name (the file's stem) and its text. The
// build writes one `const KernelSource` per cl_kernels/*.cl into
// build/generated/embedded_kernels.hpp (cmake/EmbedKernels.cmake): a stage compiles its
// program with ClContext::build(kernel_source::integrate, …).
#pragma once

namespace fdem {

struct KernelSource {
  const char* stage;
  const char* text;
};

}  // namespace fdem
