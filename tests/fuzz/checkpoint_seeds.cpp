// Seeds for fuzz_checkpoint: checkpoints written by the project's own writer
// (io::write_checkpoint_file), stamped for the empty prepared case that fuzz_checkpoint
// checks against, with one array of every stored type, an empty array, and the
// attributes `fdem check FILE.ckpt` prints. Small, so that mutations stay fast.
// Usage: fuzz_checkpoint_seeds DIR (writes DIR/seed-*.ckpt).
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/model/checkpoint_identity.hpp"
#include "io/checkpoint_file.hpp"

namespace {

template <typename T>
fdem::io::CheckpointArray array(const std::string& name, fdem::io::ArrayType type, size_t width, std::vector<T> values) {
  fdem::io::CheckpointArray a;
  a.name = name;
  a.type = type;
  a.width = width;
  a.bytes.resize(values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(a.bytes.data(), values.data(), a.bytes.size());
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  using fdem::io::ArrayType;
  const std::string dir = argv[1];
  std::filesystem::create_directories(dir);
  const fdem::PreparedCase empty_case;

  fdem::io::CheckpointData full;
  full.text["case_path"] = "cases/geostatic/case.toml";
  full.text["title"] = "seed";
  full.text["device"] = "Portable Computing Language: cpu";
  full.integers["step"] = 20;
  full.integers["broken_ce4"] = 3;
  full.numbers["time"] = 0.25;
  full.numbers["dt"] = 1e-3;
  full.numbers["worst_energy_error"] = 1e-4;
  full.arrays.push_back(array<double>("position", ArrayType::Float64, 2, {0, 0, 1, 0, 0, 1, 1, 1}));
  full.arrays.push_back(array<float>("frame_values", ArrayType::Float32, 1, {1.5f, -2.0f, 3.25f}));
  full.arrays.push_back(array<int32_t>("triangles", ArrayType::Int32, 3, {0, 1, 2, 1, 3, 2}));
  full.arrays.push_back(array<uint32_t>("contact_pairs", ArrayType::UInt32, 2, {0, 1}));
  full.arrays.push_back(array<int64_t>("break_steps", ArrayType::Int64, 1, {-1, 7}));
  full.arrays.push_back(array<uint64_t>("counters", ArrayType::UInt64, 1, {42}));
  full.arrays.push_back(array<uint8_t>("ce4_state", ArrayType::UInt8, 1, {0, 1, 2, 0}));
  full.arrays.push_back(array<double>("energy_slots", ArrayType::Float64, 4, {}));
  fdem::stamp_checkpoint(full, empty_case);
  fdem::io::write_checkpoint_file(dir + "/seed-full.ckpt", full);

  fdem::io::CheckpointData minimal;
  fdem::stamp_checkpoint(minimal, empty_case);
  fdem::io::write_checkpoint_file(dir + "/seed-minimal.ckpt", minimal);

  // Stamped for another case: the identity check's refusals.
  fdem::io::CheckpointData other = full;
  other.text["settings"] = "material.0.young = 3e10\ntime.end = 1\n";
  other.text["format_version"] = "5";
  fdem::io::write_checkpoint_file(dir + "/seed-other.ckpt", other);
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".prev") std::filesystem::remove(entry.path());
  return 0;
}
