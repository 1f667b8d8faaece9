// Fuzz target: checkpoint files (io/checkpoint_file.cpp: netCDF CDF-5 through libnetcdf,
// the attributes, the arrays and their checksum), then what `fdem check FILE.ckpt`
// prints and the restart's identity check (engine/model/checkpoint_identity.cpp check_fits)
// against an empty prepared case: the seeds (tests/fuzz/checkpoint_seeds.cpp) are stamped
// for that case, so a seed passes every check and mutations reach each refusal.
// Inputs whose netCDF header does not fit in the file are not passed on (netcdf_header.hpp:
// they crash libnetcdf itself; the two recorded ones wait for the reader to refuse them).
// Set FDEM_FUZZ_RAW_NETCDF=1 to pass every input (and find those again).
#include <cstdlib>
#include <string>

#include "engine/model/checkpoint_identity.hpp"
#include "engine/run/run.hpp"
#include "fuzz_common.hpp"
#include "io/checkpoint_file.hpp"
#include "io/netcdf_header.hpp"

namespace {
bool raw_netcdf = false;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fdem::fuzz::no_programs();
  const char* raw = std::getenv("FDEM_FUZZ_RAW_NETCDF");
  raw_netcdf = raw && std::string(raw) == "1";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fdem::PreparedCase empty_case;
  if (!raw_netcdf && !fdem::io::CdfHeader(std::string(reinterpret_cast<const char*>(data), size)).fits()) return -1;
  const std::string path = fdem::fuzz::write_input("run.ckpt", data, size);
  try {
    const fdem::io::CheckpointData ckpt = fdem::io::read_checkpoint_file(path);
    // `fdem check FILE.ckpt` (engine/main.cpp check_checkpoint) looks these up.
    size_t seen = 0;
    for (const char* key : {"format_version", "case_path", "title", "device", "precision", "mesh_hash"})
      seen += ckpt.text.count(key) ? ckpt.text.at(key).size() : 0;
    for (const char* key : {"step", "broken_ce4"}) seen += ckpt.integers.count(key);
    for (const char* key : {"time", "dt", "worst_energy_error"}) seen += ckpt.numbers.count(key);
    for (const auto& a : ckpt.arrays) seen += a.items();
    fdem::check_fits(ckpt, empty_case, path);
    (void)seen;
  } catch (const fdem::InputError&) {
  }
  return 0;
}
