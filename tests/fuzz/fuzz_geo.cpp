// Fuzz target: the .geo text as io::mesh_geo handles it before gmsh runs (reading the
// file, the cache name from its hash and the size, the search for gmsh). PATH is empty,
// so gmsh never runs: every input ends in mesh_geo's InputError. The first byte picks the
// size passed on (0: the .geo's own default), the rest is the .geo text.
#include <string>

#include "fuzz_common.hpp"
#include "io/gmsh_reader.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fdem::fuzz::no_programs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const double sizes[] = {0.0, 1e-4, 0.05, 1.0, 5.0, 1e300, 4.9e-324, 0.7e-3};
  double mesh_size = 0.0;
  if (size > 0) {
    mesh_size = sizes[data[0] % (sizeof sizes / sizeof sizes[0])];
    ++data;
    --size;
  }
  const std::string path = fdem::fuzz::write_input("model.geo", data, size);
  try {
    fdem::io::mesh_geo(path, mesh_size, fdem::fuzz::scratch_dir() + "/cache");
  } catch (const fdem::InputError&) {
  }
  return 0;
}
